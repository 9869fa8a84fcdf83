"""No run leaves a process behind: the Xvfb the kit starts dies with the run on SIGTERM (what CI sends
a cancelled or timed-out job) and on SIGKILL, alone, under pytest, and under pytest-xdist.

Each case starts a real process with ``DISPLAY`` unset, waits until the kit's Xvfb runs as its child
(or grandchild, under xdist), records those pids, kills the run, and polls ``/proc`` until they are
gone. Only processes these tests start are looked at and signalled: other people's servers on the
same machine are none of their business.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from conformance import backends
from conformance.backends import display

pytestmark = [
    pytest.mark.skipif(not sys.platform.startswith("linux") or display.shutil.which("Xvfb") is None,
                       reason="needs Linux /proc and Xvfb"),
    # FURY 2 renders through Vulkan with no X server: the kit starts no Xvfb there, which
    # test_fury2_renders_without_a_display (below, run in that environment) shows. The pytest and
    # xdist children these tests kill are started by the same code on both backends.
    pytest.mark.skipif(backends.NAME != "vtk", reason="FURY 2 starts no Xvfb: nothing of it to leave behind"),
]

#: Seconds a killed run's processes get to go away (a worker finishes the picture it is taking first).
GONE_WITHIN = 60.0


def _stat(pid: int) -> tuple[str, str, int] | None:
    """(command name, state, parent pid) of a process, or None once it is gone."""
    try:
        text = Path(f"/proc/{pid}/stat").read_text()
    except (FileNotFoundError, ProcessLookupError):
        return None
    name = text[text.index("(") + 1:text.rindex(")")]
    state, ppid = text[text.rindex(")") + 2:].split()[:2]
    return name, state, int(ppid)


def _alive(pid: int) -> bool:
    """Running: a zombie has exited, it only waits for a parent (here often pid 1) to reap it."""
    stat = _stat(pid)
    return stat is not None and stat[1] != "Z"


def _descendants(root: int) -> list[int]:
    children: dict[int, list[int]] = {}
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit() and (stat := _stat(int(entry.name))) is not None:
            children.setdefault(stat[2], []).append(int(entry.name))
    found, todo = [], [root]
    while todo:
        for child in children.get(todo.pop(), []):
            found.append(child)
            todo.append(child)
    return found


def _xvfbs(root: int) -> list[int]:
    return [pid for pid in _descendants(root) if (stat := _stat(pid)) and stat[0] == "Xvfb" and stat[1] != "Z"]


def _wait_for_xvfbs(process: subprocess.Popen, count: int, timeout: float = 240.0) -> list[int]:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        found = _xvfbs(process.pid)
        if len(found) >= count:
            return found
        if process.poll() is not None:
            out = process.stdout.read() if process.stdout else ""
            pytest.fail(f"the run ended (status {process.returncode}) before {count} Xvfb ran:\n{out[-3000:]}")
        time.sleep(0.05)
    process.kill()
    pytest.fail(f"no {count} Xvfb under pid {process.pid} within {timeout} s")


def _assert_gone(pids: list[int], what: str) -> None:
    deadline = time.monotonic() + GONE_WITHIN
    while time.monotonic() < deadline and any(_alive(pid) for pid in pids):
        time.sleep(0.05)
    left = [(pid, _stat(pid)) for pid in pids if _alive(pid)]
    for pid, _ in left:  # clean up after a failure, so one failing case does not leak into the next
        os.kill(pid, signal.SIGKILL)
    assert not left, f"{what} left behind: {left}"


def _environment(directory) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k != "DISPLAY"}
    env["PYTHONUNBUFFERED"] = "1"
    # A process killed here cannot remove its temporary files (the crash journal's directory under
    # pytest-xdist): they go to this test's own directory, which pytest prunes, not the machine's /tmp.
    env["TMPDIR"] = str(directory)
    return env


def _start(argv: list[str], cwd) -> subprocess.Popen:
    return subprocess.Popen(argv, cwd=cwd, env=_environment(cwd), stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            text=True)


def _kill(process: subprocess.Popen, signum: int) -> int:
    process.send_signal(signum)
    try:
        process.wait(GONE_WITHIN)
    except subprocess.TimeoutExpired:
        process.kill()
        process.wait()
        pytest.fail(f"the run did not end within {GONE_WITHIN} s of {signal.Signals(signum).name}")
    return process.returncode


#: Renders a picture (so an X connection is open, as in a real run), says its Xvfb, then waits.
RENDER_AND_WAIT = """
import os, time
from conformance import backends, sync
from conformance.sync import runner
from conformance.backends import display
with runner.running("free_fall", sync.load("reference")) as run:
    backends.render(run.drawing, run.scene.camera, (64, 48))
    print("xvfb", display.server_pid(), os.environ["DISPLAY"], flush=True)
    time.sleep(300)
"""


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGKILL], ids=["SIGTERM", "SIGKILL"])
@pytest.mark.full("kills whole kit runs and waits for their processes to go: robustness, not discrimination")
def test_a_process_that_started_the_display_leaves_no_xvfb(tmp_path, signum):
    process = _start([sys.executable, "-c", RENDER_AND_WAIT], tmp_path)
    said = []
    while not (line := process.stdout.readline()).startswith("xvfb ") and line:  # "" once it has ended
        said.append(line)
    assert line, f"the process ended (status {process.wait()}) without starting a display:\n{''.join(said)[-3000:]}"
    _, pid, name = line.split()
    assert _xvfbs(process.pid) == [int(pid)]
    status = _kill(process, signum)
    # Died of the signal, as the default disposition would have it (a shell shows 128 + signal).
    assert status == -signum
    _assert_gone([int(pid)], "Xvfb")
    # Xvfb went away by SIGTERM in both cases (the handler; the parent-death signal), so it cleaned up.
    assert not Path(f"/tmp/.X{name.lstrip(':')}-lock").exists()


def _pytest(tmp_path, *args: str) -> subprocess.Popen:
    # Every picture check of every scene: far longer than it takes to kill it once a display runs.
    return _start([sys.executable, "-m", "pytest", "--pyargs", "conformance", "-p", "no:cacheprovider", "-q",
                   "-k", "test_golden_render", *args], tmp_path)


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGKILL], ids=["SIGTERM", "SIGKILL"])
@pytest.mark.full("kills whole kit runs and waits for their processes to go: robustness, not discrimination")
def test_a_pytest_run_leaves_no_xvfb(tmp_path, signum):
    process = _pytest(tmp_path)
    xvfbs = _wait_for_xvfbs(process, 1)
    status = _kill(process, signum)
    assert status == -signum
    _assert_gone(xvfbs, "Xvfb")


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGKILL], ids=["SIGTERM", "SIGKILL"])
@pytest.mark.full("kills whole kit runs and waits for their processes to go: robustness, not discrimination")
def test_killing_the_xdist_controller_leaves_no_worker_and_no_xvfb(tmp_path, signum):
    pytest.importorskip("xdist")
    process = _pytest(tmp_path, "-n", "2")
    xvfbs = _wait_for_xvfbs(process, 2)  # one per worker, each its worker's child
    # A descendant may exit between the listing and its stat (a short-lived helper): it is no worker to watch.
    workers = [pid for pid in _descendants(process.pid)
               if pid not in xvfbs and (stat := _stat(pid)) is not None and stat[0] != "Xvfb"]
    assert workers, "no worker processes found"
    status = _kill(process, signum)
    assert status == -signum
    # The workers notice their controller is gone and end; each stops its Xvfb on the way out, and
    # would take it along by the parent-death signal if it were killed instead.
    _assert_gone(workers + xvfbs, "workers or their Xvfb")


@pytest.fixture
def own_display(monkeypatch):
    """This process as if it had no display yet, whatever earlier tests in it started."""
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.setattr(display, "_started", None)
    monkeypatch.setattr(display, "_on_stop", [])
    previous = signal.signal(signal.SIGTERM, signal.SIG_DFL)
    yield
    signal.signal(signal.SIGTERM, previous)


def test_the_sigterm_handler_is_installed_only_while_the_kit_owns_a_display(own_display):
    with display.virtual_display():
        assert signal.getsignal(signal.SIGTERM) is display._on_sigterm
        pid = display.server_pid()
        assert pid is not None and _alive(pid)
    assert signal.getsignal(signal.SIGTERM) is signal.SIG_DFL
    assert not _alive(pid) and display.server_pid() is None and "DISPLAY" not in os.environ


def test_a_display_already_set_is_used_and_never_stopped(own_display, monkeypatch):
    monkeypatch.setenv("DISPLAY", ":4711")
    with display.virtual_display():
        assert display.ensure_display() == ":4711" and display.server_pid() is None
        assert signal.getsignal(signal.SIGTERM) is signal.SIG_DFL
    assert os.environ["DISPLAY"] == ":4711"


def test_a_handler_someone_else_installed_is_left_alone(own_display):
    def theirs(signum, frame):
        pass

    signal.signal(signal.SIGTERM, theirs)
    with display.virtual_display():
        assert signal.getsignal(signal.SIGTERM) is theirs and display.server_pid() is not None
    assert signal.getsignal(signal.SIGTERM) is theirs


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGKILL], ids=["SIGTERM", "SIGKILL"])
@pytest.mark.full("kills whole kit runs and waits for their processes to go: robustness, not discrimination")
def test_the_run_command_leaves_no_pytest_and_no_xvfb(tmp_path, signum):
    """``python -m conformance run`` starts pytest as a child: killing the command ends that run too."""
    process = _start([sys.executable, "-m", "conformance", "run", "-q", "-k", "test_golden_render"], tmp_path)
    xvfbs = _wait_for_xvfbs(process, 1)
    children = _descendants(process.pid)
    status = _kill(process, signum)
    assert status == -signum
    _assert_gone(children, "the pytest run or its Xvfb")
    assert set(xvfbs) <= set(children)


def test_a_child_run_does_not_borrow_this_processs_xvfb(monkeypatch):
    """A pytest run the kit starts (verdicts, kill-rate, the discrimination test) starts its own display
    rather than use the Xvfb of the process that started it, which may stop first (it did: a test that
    restarted the display made four background runs exit 1 with their checks half done)."""
    monkeypatch.delenv("DISPLAY", raising=False)
    with display.virtual_display():
        assert os.environ["DISPLAY"] and "DISPLAY" not in display.child_environment()
    monkeypatch.setenv("DISPLAY", ":77")  # a display someone else runs is passed on
    assert display.child_environment()["DISPLAY"] == ":77"
