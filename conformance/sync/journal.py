"""The worker's half of crash isolation (:mod:`conformance.session.isolation` is the controller's): where this
process is in the sync under test, noted before every call into it, so that the process that outlives a
crash can say where it happened; and the crashes already seen, so a crashed scene is not run again.

Without a crash directory from the controller (a run in pytest's own process) every call here does nothing.
"""

from __future__ import annotations

import faulthandler
import hashlib
import json
import os
import time
from pathlib import Path

from conformance.errors import SyncCrashed

__all__ = ["INPUT_KEY", "Journal", "at", "check_not_crashed", "crash_file", "noting", "returned", "start_journal", "when"]

#: The key of xdist's ``workerinput`` that hands a worker the controller's crash directory.
INPUT_KEY = "conformance_crash_dir"
_RECORD_SIZE = 4096

_journal: "Journal | None" = None


class Journal:
    """Where this worker is: the check, the sync's scene and step, rewritten in place before each call
    into the sync, so that it is on disk (in the page cache) whatever kills the process next."""

    def __init__(self, directory: Path, worker: str):
        self.directory = directory
        self._fd = os.open(directory / f"{worker}.where", os.O_RDWR | os.O_CREAT | os.O_TRUNC, 0o600)
        self._stack = open(directory / f"{worker}.stack", "w")  # noqa: SIM115 - open for the process's life
        faulthandler.enable(file=self._stack, all_threads=False)
        self.nodeid = ""
        self.where: dict = {}

    def note(self, **where) -> None:
        self.where = where
        data = json.dumps({"nodeid": self.nodeid, "pid": os.getpid(), **where}).encode("utf-8")[:_RECORD_SIZE - 1]
        os.pwrite(self._fd, data.ljust(_RECORD_SIZE, b" "), 0)

    def crashed(self, spec: str, scene: str) -> dict | None:
        path = crash_file(self.directory, spec, scene)
        return json.loads(path.read_text()) if path.exists() else None


def start_journal(config) -> None:
    """In a worker given a crash directory by the controller: keep the journal from now on."""
    global _journal
    directory = getattr(config, "workerinput", {}).get(INPUT_KEY)
    if directory:
        _journal = Journal(Path(directory), config.workerinput["workerid"])


def noting(nodeid: str) -> None:
    """The check that starts now (``pytest_runtest_logstart``)."""
    if _journal is not None:
        _journal.nodeid = nodeid
        _journal.note(scene=None, step=None)


def at(scene: str, step: int | None) -> None:
    """The sync is about to be called on ``scene`` at ``step`` (``None``: its factory); the controller's
    watchdog (:class:`Watchdog`) times the call from now."""
    if _journal is not None:
        _journal.note(scene=scene, step=step, since=time.time())


def returned() -> None:
    """The call into the sync returned (or raised): the watchdog stops timing it; where it was stays noted."""
    if _journal is not None and _journal.where.get("since") is not None:
        _journal.note(**{**_journal.where, "since": None})


def check_not_crashed(spec: str, scene: str) -> None:
    """Raise :class:`SyncCrashed` when ``spec`` already crashed a worker on ``scene`` in this run."""
    crash = _journal.crashed(spec, scene) if _journal is not None else None
    if crash is not None:
        raise SyncCrashed(
            f"sync implementation {spec!r} crashed the process on scene {scene!r} {when(crash['step'])} in "
            f"{crash['nodeid']} ({crash['how']}); this check would run the scene with it again, so it fails "
            "without running (see that check's failure for the stack).")


def when(step) -> str:
    return "while being set up" if step is None else f"at step {step}"


def crash_file(directory: Path, spec: str, scene: str) -> Path:
    """Where a crash of ``spec`` on ``scene`` is kept: per sync, since a check may also run the kit's own."""
    return directory / "crashed" / hashlib.sha1(f"{spec}\0{scene}".encode()).hexdigest()
