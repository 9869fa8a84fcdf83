"""A sync that crashes the interpreter fails the checks it crashed, and the run goes on.

A segfault, an ``abort()`` or an ``os._exit`` in the sync under test cannot be caught in the process it
happens in, so the checks run in a worker process (pytest-xdist's, one worker when the run is serial)
and the process that started pytest survives to give the verdict. What is guaranteed:

* **Isolation** (``--conformance-isolation`` / ini ``conformance_isolation``): ``auto``, the default, runs
  a serial run in one worker process when the sync under test is not one of the kit's own (the short
  names of :data:`conformance.implementations.SHORT_NAMES`, which are tested here and do not crash); ``process``
  does so for any sync; ``none`` runs in pytest's own process, where a crash ends the run as it would
  without the kit. A run given ``-n`` is already in workers. It is not isolated under ``--pdb`` or
  ``--trace`` (a debugger needs the test in the terminal's process), nor without pytest-xdist.
* **A crash is a verdict.** Each worker notes, before every call into the sync, the check, the scene and
  the step (one ``pwrite`` into a small file: :class:`conformance.sync.journal.Journal`), and has :mod:`faulthandler` write the
  stack to a file when the process dies of a signal. When a worker dies, its check fails with one
  paragraph: "the process crashed", the signal or exit status, the scene and step, the sync's stack
  as faulthandler wrote it (Python frames, innermost last; a native library's own frames are not
  available to Python 3.11), and how to reproduce it. The per-scene verdict, the JSON report and
  ``report.html`` count it like any failure; pytest-xdist starts a new worker for the other checks.
* **One crash per scene.** A check that would run a crashed scene with the same sync again fails at once,
  naming the crash, instead of crashing another worker (:class:`~conformance.errors.SyncCrashed`): so
  a sync that crashes everywhere costs one worker start per scene (under ``-n``, one per worker that was
  already running one of that scene's checks), and xdist's limit on restarts is raised to cover every scene.
* Nothing is left behind: a worker's Xvfb dies with it (:mod:`conformance.backends.display`), and the crash files
  live in a temporary directory the controller removes at the end.
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import tempfile
import threading
import time
from pathlib import Path

import pytest

from conformance.sync.journal import INPUT_KEY, crash_file, when

__all__ = ["Controller", "Watchdog", "allow_restarts", "arrange", "hard_limit"]

#: Restarts allowed beyond xdist's own (four per worker): one crash per scene at most (see above).
_RESTARTS_PER_SCENE = 1


def arrange(config, sync_spec: str, mode: str) -> bool:
    """Before pytest-xdist reads its options (``pytest_cmdline_main``): ask for one worker when the run
    is serial and ``mode`` says to isolate it. Returns whether the run will be in workers."""
    from conformance.implementations import SHORT_NAMES

    if hasattr(config, "workerinput") or not config.pluginmanager.hasplugin("xdist"):
        return False
    if config.option.numprocesses is not None:  # -n given (0 included): the user chose
        return bool(config.option.numprocesses)
    if (mode == "none" or (mode == "auto" and sync_spec in SHORT_NAMES) or config.option.collectonly
            or config.getoption("usepdb", False) or config.getoption("trace", False)):
        return False
    config.option.numprocesses = 1
    return True


def allow_restarts(config, scenes: int) -> None:
    """Raise xdist's cap on replaced workers (4 per worker) by one per scene, unless the user set it."""
    if config.option.maxworkerrestart is None:
        workers = config.option.numprocesses if isinstance(config.option.numprocesses, int) else os.cpu_count() or 1
        config.option.maxworkerrestart = str(4 * workers + _RESTARTS_PER_SCENE * scenes)


# -- in the controller ------------------------------------------------------------------------------

class Controller:
    """The pytest-xdist controller's side: a crash directory for the workers, and a crashed worker's
    check turned into the kit's failure paragraph and record."""

    def __init__(self, config, sync_spec: str, record_property: str, sync_limit: float | None = None):
        self.config, self.sync_spec, self.record_property = config, sync_spec, record_property
        self.directory = Path(tempfile.mkdtemp(prefix="conformance-crashes-"))
        (self.directory / "crashed").mkdir()
        limit = hard_limit(sync_limit)
        self.watchdog = Watchdog(self.directory, limit) if limit else None

    def pytest_configure_node(self, node) -> None:
        node.workerinput[INPUT_KEY] = str(self.directory)

    @pytest.hookimpl(wrapper=True)
    def pytest_runtestloop(self, session):
        """``-x`` / ``--maxfail`` reached in a worker ends pytest-xdist's run as an interruption (exit
        status 2); in pytest's own process the same run ends with its failures (exit status 1), which
        is what scripts and ``kill-rate`` read. Say it as pytest does."""
        try:
            return (yield)
        except KeyboardInterrupt as exc:  # xdist's own Interrupted, not pytest's
            if session.testsfailed and str(exc).startswith("stopping after") and session.config.option.maxfail:
                session.shouldfail = str(exc)
                return True
            raise

    def pytest_handlecrashitem(self, crashitem: str, report, sched) -> None:
        worker = report.node.gateway.id
        where = self._read_where(worker, crashitem)
        how = _how_it_died(report.node)
        hung = self.directory / f"{worker}.hung"
        if hung.exists():
            how = (f"stopped by the kit after {_read(hung).strip()} s in one call: the per-call time limit could not "
                   "interrupt it, so it is looping in C code, where Python's alarm is never delivered")
            hung.unlink()
        stack = _read(self.directory / f"{worker}.stack")
        scene, step = where.get("scene"), where.get("step")
        if scene is not None:
            from conformance.files import write_atomically

            write_atomically(crash_file(self.directory, self.sync_spec, scene), json.dumps(
                {"nodeid": crashitem, "step": step, "how": how}).encode("utf-8"))
        place = (f"while sync implementation {self.sync_spec!r} ran on scene {scene!r} {when(step)}" if scene
                 else "outside any call into the sync (the kit's own work, or the sync's module)")
        message = (f"the process crashed ({how}) {place}. The run went on in a new process; this scene's other "
                   "checks with this sync fail without running it again.\n"
                   f"Where it was (faulthandler, innermost call last):\n{_stack_lines(stack)}\n"
                   f"reproduce (in one process): {_reproduce(self.sync_spec, scene, crashitem)}")
        report.longrepr = message
        report.when = "call"
        report.location = (report.location[0], None, crashitem.split("::", 1)[-1])  # the check's name as its heading
        report.user_properties.append((self.record_property, {
            "nodeid": crashitem, "check": _check_name(crashitem), "scene": scene, "when": "call",
            "outcome": "failed", "verdict": "failed", "worst": None,
            "kinds": {"crashed": {"value": None, "limit": None, "unit": "", "ratio": float("inf"), "at_least": False,
                                  "frame": step, "target": None, "message": message.splitlines()[0],
                                  "failures": 1}},
            "message": message.splitlines()[0], "diagnosis": "",
            "reproduce": _reproduce(self.sync_spec, scene, crashitem)}))
        self._report_row(crashitem, scene, step, message)

    def _report_row(self, crashitem: str, scene, step, message: str) -> None:
        """The crash as a row of ``report.html`` (kind ``crashed``, no pictures: the process that would
        have drawn them is gone), written by the controller, which outlives it."""
        from conformance.checks import image_options
        from conformance.reports import artefacts
        from conformance.rendering.records import ImageCheck

        reproduce = next((line.split(": ", 1)[1] for line in message.splitlines() if line.startswith("reproduce")), "")
        record = ImageCheck(kind="crashed", scene=scene or "?", frame=step if isinstance(step, int) else -1, passed=False,
                            message=message, sync=self.sync_spec, reproduce=reproduce, nodeid=crashitem)
        artefacts.append_record(record, image_options.from_config(self.config).results)

    def _read_where(self, worker: str, crashitem: str) -> dict:
        try:
            where = json.loads(_read(self.directory / f"{worker}.where").strip() or "{}")
        except ValueError:
            return {}
        return where if where.get("nodeid") == crashitem else {}

    def pytest_unconfigure(self, config) -> None:
        if self.watchdog is not None:
            self.watchdog.stop()
        shutil.rmtree(self.directory, ignore_errors=True)


def hard_limit(sync_limit: float | None) -> float | None:
    """Seconds after which the controller stops a worker stuck in one sync call: twice the per-call limit
    and 5 s more (the alarm repeats every second, so a call Python can interrupt has long given way);
    None when calls have no limit."""
    from conformance.sync import time_limit

    limit = time_limit.DEFAULT if sync_limit is None else sync_limit
    return 2 * limit + 5 if limit else None


class Watchdog:
    """The controller's thread that stops a worker stuck in one call into the sync past ``limit`` seconds.

    The per-call limit is ``SIGALRM``, which Python delivers only between bytecodes: a sync looping in C
    (``list(map(f, itertools.repeat(x)))``, a machine-made mutant of the reference) never returns, holds
    the GIL, and grew by 130 MB a second until the machine ran out of memory (24 GB). The worker notes when
    each call starts and returns (:class:`Journal`); this thread, in another process, reads the notes once
    a second and sends ``SIGABRT`` to a worker past the limit, whose faulthandler writes the stack; the
    crash then becomes the check's failure like any other, saying why it was stopped."""

    def __init__(self, directory: Path, limit: float):
        self.directory, self.limit = directory, limit
        self._stopped = threading.Event()
        self._thread = threading.Thread(target=self._watch, name="conformance-watchdog", daemon=True)
        self._thread.start()

    def stop(self) -> None:
        self._stopped.set()

    def _watch(self) -> None:
        while not self._stopped.wait(1.0):
            for path in self.directory.glob("*.where"):
                try:
                    where = json.loads(_read(path).strip() or "{}")
                except ValueError:
                    continue
                since, pid = where.get("since"), where.get("pid")
                if since is None or pid is None or time.time() - since <= self.limit:
                    continue
                hung = path.with_suffix(".hung")
                if hung.exists():
                    continue
                hung.write_text(f"{time.time() - since:.0f}")
                try:
                    os.kill(pid, signal.SIGABRT)
                except ProcessLookupError:
                    hung.unlink()


def _read(path: Path) -> str:
    try:
        return path.read_text(errors="replace")
    except OSError:
        return ""


def _how_it_died(node) -> str:
    """The worker's signal or exit status, from the process pytest-xdist started."""
    popen = getattr(getattr(node.gateway, "_io", None), "popen", None)
    try:
        code = popen.wait(timeout=5) if popen is not None else None
    except Exception:  # still running, or not a local process: say what is known
        code = None
    if code is None:
        return "the worker process went away"
    if code < 0:
        try:
            return f"killed by {signal.Signals(-code).name}"
        except ValueError:
            return f"killed by signal {-code}"
    return f"exit status {code}, without a Python error: os._exit() or a native exit()"


def _stack_lines(stack: str) -> str:
    """faulthandler's dump of the crashing thread, innermost call last, without pytest's and xdist's frames."""
    lines = [line.strip() for line in stack.splitlines() if line.strip().startswith("File ")]
    ours = [line for line in lines if "/_pytest/" not in line and "/pluggy/" not in line
            and "/xdist/" not in line and "/execnet/" not in line and '"<string>"' not in line]
    ours.reverse()  # faulthandler prints the innermost call first
    header = next((line.strip() for line in stack.splitlines() if line.startswith("Fatal Python error")), "")
    body = "\n".join(f"  {line}" for line in ours[-12:])
    if not body and stack.strip():  # not the dump's usual shape: show what it did write
        body = "\n".join(f"  {line}" for line in stack.strip().splitlines()[-12:])
    return (header + "\n" if header and header not in body else "") + (
        body or "  (no stack: the process ended without a fatal signal, or before faulthandler could write)")


def _check_name(nodeid: str) -> str:
    return nodeid.split("::")[-1].split("[")[0]


def _reproduce(sync_spec: str, scene: str | None, nodeid: str) -> str:
    """The crashed check alone, in one process, with the scene's source for a user's scene."""
    import shlex

    from conformance.sync import own_scenes, printed

    source = own_scenes.scene_arguments(scene) if scene else []
    return shlex.join([*printed.pytest(), "--pyargs", "conformance", "--sync", sync_spec, *source,
                       "--conformance-isolation", "none", "-k", _test_words(nodeid)])


def _test_words(nodeid: str) -> str:
    name = nodeid.split("::")[-1]
    check, _, params = name.partition("[")
    return " and ".join([check, *[p for p in params.rstrip("]").split("-") if p.isidentifier()]])
