"""A pytest run forked from the app server (:mod:`conformance.discrimination.forked`) is the run a new
process gives: the same exit status and records, the sync found through ``PYTHONPATH``, the kit's asserts
rewritten (no warning that they could not be), a run past its time limit stopped, and what is forked
for a kit that is killed (a pytest run, an app) ended with it."""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from conformance.apps import launch
from conformance.discrimination import forked, verdicts

#: a sync that draws nothing: fails the first vertex check of free_fall
NOTHING = textwrap.dedent("""
    class DrawsNothing:
        def __init__(self, world):
            pass

        def __call__(self):
            pass
""")


@pytest.fixture
def env(tmp_path):
    (tmp_path / "draws_nothing.py").write_text(NOTHING, encoding="utf-8")
    environ = dict(os.environ)
    environ["PYTHONPATH"] = os.pathsep.join([str(tmp_path), *filter(None, environ.get("PYTHONPATH", "").split(os.pathsep))])
    return environ


def test_a_forked_run_is_the_run_a_new_process_gives(env):
    args = dict(stop_at_first=True, env=env, pytest_args=["--conformance-isolation", "none", "-k", "free_fall and poses_every_frame"])
    new, fork = (verdicts.check("draws_nothing:DrawsNothing", fork=f, **args) for f in (False, True))
    assert fork.exitstatus == new.exitstatus == pytest.ExitCode.TESTS_FAILED, (fork.stderr, new.stderr)
    assert [(r["check"], r["scene"], r["message"]) for r in fork.failed] == \
        [(r["check"], r["scene"], r["message"]) for r in new.failed]


def test_a_forked_run_rewrites_the_kits_asserts_as_a_new_process_does(env):
    done = forked.run(["--pyargs", "conformance", "-q", "-p", "no:cacheprovider", "-k", "test_builds_with_defaults and free_fall"],
                      env=env)
    if done is None:
        pytest.skip("no forkserver on this platform: the kit starts a new process instead")
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    assert "PytestAssertRewriteWarning" not in done.stdout + done.stderr, done.stdout[-2000:]


def test_a_forked_run_past_its_time_limit_is_stopped(env):
    with pytest.raises(subprocess.TimeoutExpired):
        forked.run(["--pyargs", "conformance", "-q", "-p", "no:cacheprovider", "--sync", "draws_nothing:DrawsNothing",
                    "-k", "tumbling"], env=env, timeout=0.5)


#: a check that says where it runs, then waits
WAITS = textwrap.dedent("""
    import os, time

    def test_waits():
        with open(os.environ["KIT_TEST_PIDFILE"], "w") as f:
            f.write(str(os.getpid()))
        time.sleep(120)
""")

#: an app that says where it runs, then waits
WAITING_APP = textwrap.dedent("""
    import os, time

    with open(os.environ["KIT_TEST_PIDFILE"], "w") as f:
        f.write(str(os.getpid()))
    time.sleep(120)
""")

#: a caller: a forked pytest run of test_waits.py, or a run of the waiting app
CALLERS = {
    "pytest run": "from conformance.discrimination import forked; import os; "
                  "forked.run(['test_waits.py', '-q', '-p', 'no:cacheprovider'], env=dict(os.environ))",
    "app": "from conformance.apps import launch; launch.record('waiting_app.py', ticks=1)",
}


def _gone(pid: int, within: float) -> bool:
    deadline = time.monotonic() + within
    while time.monotonic() < deadline:
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            return True
        time.sleep(0.1)
    return False


@pytest.mark.parametrize("what", sorted(CALLERS))
def test_what_is_forked_for_a_killed_kit_ends_with_it(what, tmp_path, env):
    """The fork server outlives the kit that started it while anything it forked runs, so what it forked
    ends with the kit itself: a ``precision`` run stopped with ``SIGTERM`` left its pytest run going."""
    if launch.server() is None:
        pytest.skip("no forkserver on this platform: the kit starts a new process instead")
    (tmp_path / "test_waits.py").write_text(WAITS, encoding="utf-8")
    (tmp_path / "waiting_app.py").write_text(WAITING_APP, encoding="utf-8")
    pidfile = tmp_path / "pid"
    caller = subprocess.Popen([sys.executable, "-c", CALLERS[what]], cwd=tmp_path, env={**env, "KIT_TEST_PIDFILE": str(pidfile)},
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 120
        while not pidfile.exists() or not pidfile.read_text():
            assert caller.poll() is None and time.monotonic() < deadline, f"the {what} never started"
            time.sleep(0.1)
        pid = int(pidfile.read_text())
        caller.kill()  # SIGKILL: no handler of the kit's runs
        caller.wait()
        assert _gone(pid, within=10), f"the {what} (pid {pid}) still runs 10 s after the kit that asked for it was killed"
    finally:
        caller.kill()
        if pidfile.exists() and pidfile.read_text():
            with contextlib.suppress(ProcessLookupError):
                os.kill(int(pidfile.read_text()), signal.SIGKILL)


#: a check that kills the fork server it was forked from (its parent), then fails
KILLS_ITS_SERVER = textwrap.dedent("""
    import os, signal, time

    def test_kills_its_server_then_fails():
        os.kill(os.getppid(), signal.SIGKILL)
        time.sleep(0.5)  # the caller reads the server's end of file now, while this run goes on
        assert False
""")

#: an app that kills the fork server it was forked from, then runs as the kit's box app does
APP_KILLS_ITS_SERVER = textwrap.dedent("""
    import os, runpy, signal, time

    os.kill(os.getppid(), signal.SIGKILL)
    time.sleep(0.5)
    runpy.run_path({box!r}, run_name="__main__")
""")

#: a caller that prints what the kit made of its forked run
SERVER_KILLED_CALLERS = {
    "pytest run": "from conformance.discrimination import forked; import os; "
                  "print(forked.run(['test_kills.py', '-q', '-p', 'no:cacheprovider'], env=dict(os.environ)).returncode)",
    "app": "from conformance.apps import launch; launch.record('app_kills.py', ticks=3); print('recorded')",
}


@pytest.mark.parametrize("what", sorted(SERVER_KILLED_CALLERS))
def test_a_run_whose_fork_server_dies_keeps_its_own_exit_status(what, tmp_path, env):
    """multiprocessing reads 255 for a process whose fork server ended first, whatever the process did (a
    wrong sync's forked run read 255 in CI though its pytest run ended with 1): the kit waits for the process
    itself and goes by the status it wrote."""
    if launch.server() is None:
        pytest.skip("no forkserver on this platform: the kit starts a new process instead")
    from conformance import backends

    box = Path(__file__).parent / "apps" / f"box_{backends.NAME}.py"
    (tmp_path / "test_kills.py").write_text(KILLS_ITS_SERVER, encoding="utf-8")
    (tmp_path / "app_kills.py").write_text(APP_KILLS_ITS_SERVER.format(box=str(box)), encoding="utf-8")
    done = subprocess.run([sys.executable, "-c", SERVER_KILLED_CALLERS[what]], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=300)
    expected = {"pytest run": str(int(pytest.ExitCode.TESTS_FAILED)), "app": "recorded"}[what]
    assert done.returncode == 0 and done.stdout.strip().splitlines()[-1:] == [expected], (
        f"the {what} whose fork server died should be read as {expected}, but the caller exited "
        f"{done.returncode} printing {done.stdout[-500:]!r}; stderr {done.stderr[-1500:]}")
