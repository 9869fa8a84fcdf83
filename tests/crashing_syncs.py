"""Syncs that end the interpreter, for the crash tests (not wrong syncs: the kill rate must not pay a
worker start for each). Each is right, except at free_fall's 50th call (step 49)."""

from __future__ import annotations

import collections
import ctypes
import itertools
import os

from hanging_syncs import CALL, SCENE, MisbehavesOnFreeFall

__all__ = ["CALL", "SCENE", "AbortsOnFreeFall", "ExitsOnFreeFall", "LoopsInCOnFreeFall", "SegfaultsOnFreeFall"]


class SegfaultsOnFreeFall(MisbehavesOnFreeFall):
    """Reads address 0, as a sync holding a dangling buffer pointer might: SIGSEGV."""

    def misbehave(self):
        ctypes.string_at(0)


class AbortsOnFreeFall(MisbehavesOnFreeFall):
    """``abort()``, as a native library does on a failed assertion: SIGABRT."""

    def misbehave(self):
        os.abort()


class ExitsOnFreeFall(MisbehavesOnFreeFall):
    """``os._exit(3)``: no signal, no Python error, no stack."""

    def misbehave(self):
        os._exit(3)


class LoopsInCOnFreeFall(MisbehavesOnFreeFall):
    """Loops for ever inside one C call (a machine-made mutant of the reference did, in
    ``list(map(..., itertools.repeat(client)))``): Python's per-call alarm is never delivered; here with
    no memory growth, so that only the time limit can stop it."""

    def misbehave(self):
        collections.deque(itertools.repeat(None), maxlen=0)
