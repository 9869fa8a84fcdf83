"""``python -m pytest ARGV`` run in a process forked from the app server (:func:`conformance.apps.launch.server`),
which has imported pyBullet, FURY and its renderer, numpy, scipy and pytest once.

A wrong sync's run stops at its first failure, often within a second of its start, and starting was
much of it: six wrong syncs with ``-x``, one after the other, took 16.8 s of CPU as new processes and 11.8 s
forked on FURY 0.12, 22.1 s and about 16.8 s on FURY 2 (2026-11-28, process accounting, the server's own
start-up included): about 1 s a run. The kit's own tests make about 40 such runs a FURY.

The fork behaves as the new process would: it runs in the given directory with the given environment
(``PYTHONPATH`` put on ``sys.path`` as the interpreter would), its standard streams go to files read back
afterwards, and the kit's own modules the server imported are dropped first, so that pytest imports them
afresh and rewrites their asserts as it does in a new process. Where there is no server (no
``forkserver`` start method) the caller starts a new process instead (:func:`run` returns None)."""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
from pathlib import Path

__all__ = ["run"]


def run(argv: list[str], *, env: dict[str, str], timeout: float | None = None) -> subprocess.CompletedProcess | None:
    """Run ``python -m pytest`` with ``argv`` (the arguments after ``pytest``) in a forked process with
    ``env``, in this process's directory; its exit status (negative: the signal that ended it), stdout and
    stderr. Raises :class:`subprocess.TimeoutExpired` past ``timeout`` (the process is killed then);
    None where there is no server to fork from."""
    from conformance.apps import launch

    context = launch.server()
    if context is None:
        return None
    with tempfile.TemporaryDirectory(prefix="kit-forked-") as tmp:
        out, err, status = (os.path.join(tmp, name) for name in ("stdout", "stderr", "status"))
        process = context.Process(target=_main, args=(list(argv), dict(env), os.getcwd(), out, err, os.getpid(), status),
                                  daemon=False)
        launch.start(process)
        code = launch.join(process, timeout, Path(status))  # past the timeout, or interrupted: it does not outlive the caller
        if code is None:
            raise subprocess.TimeoutExpired(argv, timeout)
        return subprocess.CompletedProcess(argv, code, launch.read(Path(out)), launch.read(Path(err)))


def _main(argv: list[str], env: dict[str, str], cwd: str, out: str, err: str, caller: int, status: str) -> None:
    """In the forked process: what ``python -m pytest ARGV`` started in ``cwd`` with ``env`` would do."""
    import atexit

    from conformance.backends import display

    display.die_with(caller)  # the caller's end ends this run, not the server's (it outlives its caller)
    nowhere = os.open(os.devnull, os.O_RDONLY)
    os.dup2(nowhere, 0)
    os.dup2(os.open(out, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600), 1)
    os.dup2(os.open(err, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600), 2)
    os.environ.clear()
    os.environ.update(env)
    os.chdir(cwd)
    # python -m puts the directory it starts in first, then PYTHONPATH's entries, then its own path
    first = [cwd, *filter(None, env.get("PYTHONPATH", "").split(os.pathsep))]
    sys.path[:] = first + [p for p in sys.path if p and p not in first]
    sys.argv = [os.path.join(os.path.dirname(__import__("pytest").__file__), "__main__.py"), *argv]
    for name in [n for n in sys.modules if n == "conformance" or n.startswith("conformance.")]:
        del sys.modules[name]
    import pytest

    try:
        code = pytest.main(argv)
    finally:
        atexit._run_exitfuncs()  # a process of multiprocessing's ends in os._exit: the Xvfb the run started, say
        sys.stdout.flush()
        sys.stderr.flush()
    Path(status).write_text(str(int(code)), encoding="utf-8")  # what the caller goes by if the server ends first
    sys.exit(int(code))
