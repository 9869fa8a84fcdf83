"""Running an app in a process of its own and reading back what it recorded.

The app runs in a process of its own (:mod:`conformance.apps.child`), so its globals, the kit's patches,
and whatever the app does to the process (exit, crash, hang) stay there. That process is forked from a
server that has imported FURY once (:mod:`multiprocessing`'s ``forkserver``, preloading
:mod:`conformance.apps.preload`), not started afresh: importing FURY was most of a short run. It has this
process's environment, working directory and ``sys.path``, and runs ``atexit`` handlers as a Python
process does at exit. Where there is no ``forkserver`` (Windows) it is ``python -m conformance.apps.child``.
``timeout`` bounds the whole run; an app that exceeds it, crashes or refuses to hand over its loop gives
:class:`AppFailed` with one paragraph saying which. A crash is the app's unless the crashing thread was in
the kit's own code (:func:`kit_crash_site`, read from the dump faulthandler writes): then it is
:class:`KitFailed`, the kit's fault and no verdict on the app.
"""

from __future__ import annotations

import contextlib
import json
import linecache
import multiprocessing
import os
import re
import signal
import subprocess
import sys
import sysconfig
import tempfile
import threading
import time
import types
from pathlib import Path

from conformance.apps import recording as recording_mod
from conformance.errors import ConformanceError

__all__ = ["AppFailed", "KitFailed", "kit_crash_site", "read", "record", "server", "start", "start_server"]

#: seconds an app's whole run may take before the kit stops it
DEFAULT_TIMEOUT = 300.0


class AppFailed(ConformanceError):
    """The app could not be run to a recording; the message says why, in one paragraph."""


class KitFailed(ConformanceError):
    """The kit's own code failed while it ran the app: a fault of the kit, not a verdict on the app. The
    message says so, with the kit's traceback, so that it can be reported and is never read as the app's."""


def record(script: str | os.PathLike, *, ticks: int = 120, events=(), tick_function: str | None = None,
           timeout: float = DEFAULT_TIMEOUT) -> recording_mod.Recording:
    """Run the app ``script`` under the kit for up to ``ticks`` ticks, applying ``events`` (dicts as
    :func:`conformance.apps.perturb.as_dict` writes them), and return its recording."""
    script = Path(script)
    if not script.is_file():
        raise AppFailed(f"app={str(script)!r}: no such file; give the path of the Python script that runs your simulation")
    with tempfile.TemporaryDirectory(prefix="conformance-app-") as work:
        out = Path(work) / "recording.npz"
        argv = [str(script), "--out", str(out), "--ticks", str(int(ticks)), "--events", json.dumps(list(events))]
        if tick_function:
            argv += ["--tick", tick_function]
        env = dict(os.environ)
        env.setdefault("PYTHONFAULTHANDLER", "1")
        try:
            returncode, stderr = _run_child(argv, env, timeout, Path(work) / "stderr.txt")
        except subprocess.TimeoutExpired as exc:
            raise AppFailed(f"{script}: the app did not finish {ticks} ticks within {timeout:g} s and was stopped "
                            f"(a callback that never returns, or a loop of its own the kit did not take over). "
                            f"Its last output: {_tail(exc.stderr)}") from None
        fault = Path(str(out) + ".kit-error")
        if fault.exists():
            raise KitFailed(f"{script}: the kit itself failed while it ran the app, a fault of the kit and not of "
                            f"your program (nothing is judged; please report it with what follows): "
                            f"{fault.read_text(encoding='utf-8').strip()}")
        error = Path(str(out) + ".error")
        if error.exists():
            raise AppFailed(error.read_text(encoding="utf-8").strip())
        if returncode < 0:
            site = kit_crash_site(stderr)
            if site is not None:
                raise KitFailed(_kit_crash(script, -returncode, site, stderr))
        if returncode != 0 or not out.exists():
            how = f"was killed by signal {-returncode}" if returncode < 0 else f"exited with status {returncode}"
            raise AppFailed(f"{script}: the app's process {how} before the kit had its recording (the process crashed). "
                            f"Its last output: {_tail(stderr)}")
        return recording_mod.load(out)


_server_lock = threading.Lock()
_start_lock = threading.Lock()
_server = None


def server():
    """The forkserver context whose server has imported :mod:`conformance.apps.preload` (None where there is none):
    the app processes, and the kit's own pytest runs (:mod:`conformance.discrimination.forked`), are forked from it."""
    global _server
    with _server_lock:
        if _server is None and "forkserver" in multiprocessing.get_all_start_methods():
            _server = multiprocessing.get_context("forkserver")
            _server.set_forkserver_preload(["conformance.apps.preload"])
            _start_quietly()
        return _server


def start_server() -> None:
    """Start the app server now, if it is not running: its apps start in the directory it started in, so a
    process whose tests change directory starts it before they do (``tests/conftest.py``)."""
    server()


def _start_quietly() -> None:
    """Start the server with its stderr nowhere: importing pyBullet prints its "build time" there, a
    second copy of this process's own line in the kit's output. Every app process sets its own."""
    from multiprocessing import forkserver

    saved, quiet = os.dup(2), os.open(os.devnull, os.O_WRONLY)
    sys.stderr.flush()
    os.dup2(quiet, 2)
    try:
        forkserver.ensure_running()
    finally:
        os.dup2(saved, 2)
        os.close(saved)
        os.close(quiet)


def _run_child(argv: list[str], env: dict, timeout: float, stderr_path: Path) -> tuple[int, str]:
    """Run :func:`conformance.apps.child.main` on ``argv`` in a process of its own with ``env``; its exit
    status (negative: the signal that killed it) and what it wrote to stderr. Raises
    :class:`subprocess.TimeoutExpired` (with that stderr) when it runs past ``timeout``; it is killed then."""
    context = server()
    if context is None:
        command = [sys.executable, "-m", "conformance.apps.child", *argv]
        done = subprocess.run(command, capture_output=True, text=True, timeout=timeout, env=env, stdin=subprocess.DEVNULL)
        return done.returncode, done.stderr
    status_path = stderr_path.with_name("status")
    process = context.Process(target=_child_main, args=(argv, env, str(stderr_path), os.getpid(), str(status_path)),
                              daemon=False)
    start(process)
    code = join(process, timeout, status_path)  # past the timeout, or interrupted (Ctrl-C): it does not outlive the kit
    if code is None:
        raise subprocess.TimeoutExpired(argv, timeout, stderr=read(stderr_path))
    return code, read(stderr_path)


def start(process) -> None:
    """Start ``process`` with no main module for multiprocessing to import in it: it would run this
    program's script again there as ``__mp_main__``, and a script that calls :func:`record` at its top level
    (no ``if __name__ == "__main__":``) would call it again and die, silently. Nothing of ``__main__`` is sent."""
    with _start_lock:  # one swap at a time: two interleaved would leave the stand-in in place
        main = sys.modules["__main__"]
        sys.modules["__main__"] = types.ModuleType("__main__")
        try:
            process.start()
        finally:
            sys.modules["__main__"] = main


#: What multiprocessing reports as the exit status of a process forked from a server that ended before it
#: could pass the status on (its pipe read at end of file): not the process's own status.
SERVER_GONE = 255


def join(process, timeout: float | None, status_path: Path) -> int | None:
    """Wait up to ``timeout`` seconds for ``process``, forked from the server; its exit status, or None when it
    ran past ``timeout`` or the wait was interrupted (it is killed then: it never outlives the kit).

    The status is the one the server passes on, or, where the server ended first (:data:`SERVER_GONE`, and
    the process may still be running), the one the process wrote to ``status_path`` with :func:`leave` once
    it has ended. Seen once in CI: a wrong sync's forked run read 255 though its pytest run had ended with 1
    and written its report (FURY 2, cause not found); verdicts go by the process's own status."""
    deadline = None if timeout is None else time.monotonic() + timeout
    try:
        process.join(timeout)
        if process.exitcode is None:
            return None
        if process.exitcode != SERVER_GONE:
            return process.exitcode
        if not _ended(process.pid, deadline):
            return None
        try:
            return int(status_path.read_text(encoding="utf-8"))
        except (OSError, ValueError):  # it died before it could say: the server's 255 is all there is
            return SERVER_GONE
    finally:
        if process.exitcode is None:
            process.kill()
            process.join()
        elif process.exitcode == SERVER_GONE and _alive(process.pid):  # past the timeout, or interrupted
            with contextlib.suppress(OSError):
                os.kill(process.pid, signal.SIGKILL)


def _alive(pid: int) -> bool:
    """Whether ``pid`` still runs: an orphan that has ended waits as a zombie until whoever took it over (init,
    which in a container may never) reaps it, so a zombie has ended."""
    try:
        with open(f"/proc/{pid}/stat", encoding="ascii", errors="replace") as fh:
            return fh.read().rpartition(")")[2].split()[0] not in ("Z", "X")
    except FileNotFoundError:
        return False
    except OSError:  # no /proc: a signal of 0 says whether it is there (a zombie counts as running)
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            return False
        except PermissionError:
            pass
        return True


def _ended(pid: int, deadline: float | None) -> bool:
    """Wait until ``pid`` (reaped by whoever took it over) has ended, or ``deadline`` passed: whether it ended."""
    while _alive(pid):
        if deadline is not None and time.monotonic() > deadline:
            return False
        time.sleep(0.05)
    return True


def leave(code, status_path: str) -> None:
    """In a forked process: write its exit status ``code`` where :func:`join` reads it, and exit with it."""
    code = 0 if code is None else code if isinstance(code, int) else 1  # as sys.exit reads it
    with contextlib.suppress(OSError):
        Path(status_path).write_text(str(code), encoding="utf-8")
    sys.exit(code)


def read(path: Path) -> str:
    """A child's output file as text (empty if it wrote none)."""
    try:
        return path.read_text(encoding="utf-8", errors="replace")
    except FileNotFoundError:
        return ""


def _child_main(argv: list[str], env: dict, stderr_path: str, caller: int, status_path: str) -> None:
    """In the forked process: what ``python -m conformance.apps.child ARGV`` would do, with its output
    where :func:`_run_child` reads it (stdout nowhere, as before: only stderr is ever shown)."""
    import atexit
    import faulthandler

    from conformance.apps import child
    from conformance.backends import display

    display.die_with(caller)  # a kit killed mid-run leaves no app running (the server outlives it)
    quiet = os.open(os.devnull, os.O_RDWR)
    os.dup2(quiet, 0)
    os.dup2(quiet, 1)
    os.dup2(os.open(stderr_path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600), 2)
    os.environ.clear()
    os.environ.update(env)
    faulthandler.enable()
    try:
        code = child.main(argv)
    finally:
        atexit._run_exitfuncs()  # a process of multiprocessing's ends in os._exit: the app's handlers, the Xvfb it started
        sys.stdout.flush()
        sys.stderr.flush()
    leave(code, status_path)


#: The kit's own package: a crash whose innermost frame is here is the kit's.
_KIT = Path(__file__).resolve().parent.parent
#: The wrappers :func:`conformance.apps.driver.install_pybullet` puts around the app's own pyBullet calls: a
#: crash in one of them (and not deeper, in the kit's reads they call) is in the app's call, so the app's.
STAND_INS = ("connect_", "disconnect_", "step_", "write_")
#: Python's own library: its functions (``ctypes.string_at``, ``threading``'s) are how a call was made,
#: not whose call it was, so the crash is placed at the frame that called them. Not the packages installed
#: beside it (``site-packages``), which are the app's libraries.
_STDLIB = Path(sysconfig.get_paths()["stdlib"]).resolve()
_FRAME = re.compile(r'^\s*File "(?P<file>.*)", line (?P<line>\d+) in (?P<function>.*)$')


def kit_crash_site(dump: str) -> tuple[Path, int, str] | None:
    """Where the kit's own code was when the app's process crashed, from faulthandler's ``dump`` of it: the
    file, line and function of the crashing thread's innermost frame outside Python's own library (and the
    guard's hand-on of a read, :mod:`conformance.apps.guarded`), if that frame is the kit's and not one of
    the :data:`STAND_INS` (there the crash is in the app's call). None
    when the crash is the app's, or there is no dump to tell (the app's, as before: faulthandler is on in
    every app process, so a crash in the kit's frames always has one)."""
    for frame in _crashing_frames(dump):
        if frame["file"].startswith("<frozen "):
            continue
        path = Path(frame["file"]).resolve()
        if path.is_relative_to(_STDLIB) and not {"site-packages", "dist-packages"} & set(path.parts):
            continue
        if not path.is_relative_to(_KIT):
            return None
        if path == _KIT / "apps" / "driver.py" and frame["function"] in STAND_INS:
            return None
        if path == _KIT / "apps" / "guarded.py" and frame["function"] == "__call__":
            continue  # the guard passes a read on: the call that crashed is named where the read was asked for
        return path, int(frame["line"]), frame["function"]
    return None


def _crashing_frames(dump: str) -> list[re.Match]:
    """The frames of the thread that crashed, innermost first, in faulthandler's ``dump`` (the last one in
    it); [] if there is none."""
    lines = (dump or "").splitlines()
    fatal = max((i for i, line in enumerate(lines) if line.startswith("Fatal Python error:")), default=None)
    frames: list[re.Match] = []
    crashing = False
    for line in lines[fatal + 1:] if fatal is not None else ():
        if line.startswith(("Thread 0x", "Current thread", "Extension modules:")):
            if crashing:
                break
            crashing = line.startswith("Current thread")
        elif crashing and (frame := _FRAME.match(line)):
            frames.append(frame)
    return frames


def _kit_crash(script, number: int, site: tuple[Path, int, str], dump: str) -> str:
    """The paragraph of :class:`KitFailed` for a crash in the kit's code at ``site``."""
    path, line, function = site
    try:
        name = f"signal {number} ({signal.Signals(number).name})"
    except ValueError:
        name = f"signal {number}"
    source = linecache.getline(str(path), line).strip()
    frames = [frame[0].strip() for frame in _crashing_frames(dump)]
    return (f"{script}: the kit could not judge the program: its process was killed by {name} in the kit's own "
            f"code, not in the program's: in {function}() at {path.relative_to(_KIT.parent)}:{line}"
            + (f", `{source}`, the call that crashed" if source else "")
            + ". The program is not at fault and nothing of it is judged; this is a fault of the kit, please report "
            "it with this paragraph. The crashing thread's frames, innermost first: " + "; ".join(frames[:12]))


#: where the frames of a crash's dump are the kit's or Python's own, around the app's: left out of its last words
_OWN_FRAMES = (str(Path(__file__).resolve().parent.parent), str(Path(multiprocessing.__file__).resolve().parent),
               '"<frozen ', '"<string>"')


def _tail(text, lines: int = 12) -> str:
    """The last ``lines`` of the app's output. A crash's dump (faulthandler's) is cut to its error and the
    crashing thread's frames that are not the kit's or Python's (the app's, its libraries'): the frames the
    kit runs the app in, the other threads' stacks and the list of extension modules do not say where the
    app was."""
    if isinstance(text, bytes):
        text = text.decode("utf-8", "replace")
    kept = [line for line in (text or "").strip().splitlines()
            if "pybullet build time" not in line and not (line.lstrip().startswith('File "') and any(own in line for own in _OWN_FRAMES))]
    fatal = next((i for i, line in enumerate(kept) if line.startswith("Fatal Python error:")), None)
    if fatal is not None:
        dump, crashing = [kept[fatal]], False
        for line in kept[fatal + 1:]:
            if line.startswith(("Thread 0x", "Current thread", "Extension modules:")):
                crashing = line.startswith("Current thread")
            if crashing and line.strip():
                dump.append(line)
        kept = kept[:fatal][-2:] + dump
    return "\n".join(kept[-lines:]).strip() or "(nothing)"
