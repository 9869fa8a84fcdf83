"""Syncs that hang, for the time limit's tests (not wrong syncs: the kill rate must not wait on them)."""

from __future__ import annotations

import time

from conformance.implementations.reference import ReferenceSync

#: The scene and the call (1-based) at which :class:`HangsOnFreeFall` hangs.
SCENE, CALL = "free_fall", 50


class MisbehavesOnFreeFall(ReferenceSync):
    """Right, except that on ``free_fall`` its 50th call runs :meth:`misbehave` first."""

    def __init__(self, world):
        super().__init__(world)
        self.scene, self.calls = world.scene, 0

    def __call__(self):
        self.calls += 1
        if self.scene == SCENE and self.calls == CALL:
            self.misbehave()
        return super().__call__()


class HangsOnFreeFall(MisbehavesOnFreeFall):
    """Sleeps for an hour at that call, swallowing every Exception (as a sync waiting on a lock or a
    socket might): a time limit must still stop it."""

    def misbehave(self):
        try:
            time.sleep(3600)
        except Exception:
            pass


class InterruptedOnFreeFall(MisbehavesOnFreeFall):
    """Raises KeyboardInterrupt at that call, as Ctrl-C pressed while a sync runs: the run ends part-way
    (``tests/test_scene_verdicts.py``)."""

    def misbehave(self):
        raise KeyboardInterrupt


class CtrlCOnFreeFall(MisbehavesOnFreeFall):
    """Presses Ctrl-C at the 50th call on ``free_fall`` counted over every instance of the process (a
    profile's checks may each make fewer calls than that): SIGINT to its whole process group, as a
    terminal sends it to the command in the foreground and everything it started
    (``tests/test_kit_interrupt.py``)."""

    calls_in_this_process = 0

    def __call__(self):
        if self.scene == SCENE:
            type(self).calls_in_this_process += 1
            if type(self).calls_in_this_process == CALL:
                self.misbehave()
        return ReferenceSync.__call__(self)

    def misbehave(self):
        import os
        import signal

        os.killpg(os.getpgrp(), signal.SIGINT)
        time.sleep(5)  # the signal arrives here, as a KeyboardInterrupt
