"""The kit never crashes a program, and never blames one for its own crash (issue 47, point 6).

pyBullet 3.2.7 dies of signal 11 in ``getCollisionShapeData`` on an MJCF ``fromto`` capsule, a call the kit
makes on every frame and the app never does: a program drawing ``mjcf/ant.xml`` ran alone and was killed
under the kit, and failed ``runs`` for it. Now the kit's reads of the app's bodies are tried first in a
forked copy of the app's process (:mod:`conformance.apps.guarded`): a read that crashed the copy is never
made in the app's, and the recording says so. A crash the kit's own code causes anyway is the kit's
(``KitFailed``: "could not judge", exit 3), never the app's; a crash in the app's own code stays its own.
"""

from __future__ import annotations

import ctypes
import os
import re
import time

import pybullet
import pytest

from conformance import apps
from conformance.apps import guarded, launch

import app_sources

SOURCE = app_sources.SOURCE
STEP = "    p.stepSimulation()\n"
TICKS = 8
#: The guard and the reading of a crash's dump: pyBullet and text alone.
NO_FURY = pytest.mark.fury_free("its verdict cannot depend on the FURY: the guard on pyBullet, or a dump's text")


def _app(tmp_path, text: str):
    path = tmp_path / "app.py"
    path.write_text(text, encoding="utf-8")
    return path


# -- the guard, on a stand-in call that crashes on purpose (no pyBullet bug needed) ---------------------------

def _crashing_read(value, physicsClientId=0):
    """A read that crashes the process when asked for ``0``, as pyBullet's does on a fromto capsule."""
    if value == 0:
        ctypes.string_at(0)
    _made.append(value)
    return value * 10


_made: list = []


@pytest.fixture
def client():
    client = pybullet.connect(pybullet.DIRECT)
    yield client
    pybullet.disconnect(physicsClientId=client)


@pytest.fixture
def forks(monkeypatch):
    """How many children the guard forks."""
    counted = []
    fork = os.fork

    def counting():
        counted.append(1)
        return fork()

    monkeypatch.setattr(guarded.os, "fork", counting)
    return counted


def _plan(values):
    def plan(call, clients):
        got = []
        for client in clients:
            for value in values:
                try:
                    got.append(call(_crashing_read, value, physicsClientId=client))
                except guarded.Refused as refusal:
                    got.append(refusal)
        return got
    return plan


@NO_FURY
def test_a_read_that_crashes_a_forked_copy_is_never_made_here(client, forks):
    _made.clear()
    got = guarded.run(_plan([1, 0, 2, 0]), [client])
    assert got[0] == 10 and got[2] == 20, got
    for refusal in (got[1], got[3]):
        assert isinstance(refusal, guarded.Refused), got
        assert refusal.call == f"_crashing_read(0, physicsClientId={client})" and refusal.how == "signal 11, SIGSEGV"
    assert _made == [1, 2], "the crashing read was made in this process"
    assert len(forks) == 2, "one fork to find the crash, one for the rest"


@NO_FURY
def test_one_fork_when_nothing_crashes_and_none_for_a_client_that_is_not_direct(client, forks, monkeypatch):
    _made.clear()
    assert guarded.run(_plan([1, 2, 3]), [client]) == [10, 20, 30] and len(forks) == 1
    # A client the guard may not fork for (a GUI client's server thread is not in a child): made here, as before.
    monkeypatch.setattr(guarded, "_direct", lambda c: False)
    assert guarded.run(_plan([4]), [client]) == [40] and len(forks) == 1
    assert _made == [1, 2, 3, 4]


@NO_FURY
def test_a_child_that_hangs_is_killed_and_the_reads_are_made_here(client, forks, monkeypatch):
    parent = os.getpid()

    def slow_in_a_child(value, physicsClientId=0):
        if os.getpid() != parent:
            time.sleep(30)
        return value

    monkeypatch.setattr(guarded, "TIMEOUT", 0.3)
    start = time.perf_counter()
    assert guarded.run(lambda call, clients: call(slow_in_a_child, 7, physicsClientId=clients[0]), [client]) == 7
    assert time.perf_counter() - start < 5 and len(forks) == 1


# -- a program pyBullet crashes on when the kit reads its bodies -----------------------------------------------

def _capsule_app() -> str:
    """The box app with its box made pybullet_data's ``mjcf/capsule_fromtoX.xml`` (a plane, and a free
    capsule given by ``fromto``, on whose collision shape ``getCollisionShapeData`` crashes pyBullet), the
    actor still posed from ``getBasePositionAndOrientation`` after each step."""
    text = re.sub(r"(?m)^shape = p\.createCollisionShape\(.*\n", "import pybullet_data\n"
                  "p.setAdditionalSearchPath(pybullet_data.getDataPath())\n", SOURCE)
    text = re.sub(r"(?m)^(\w+) = p\.createMultiBody\(.*$", r'\1 = p.loadMJCF("mjcf/capsule_fromtoX.xml")[1]', text)
    assert text.count("loadMJCF") == 1 and "createCollisionShape" not in text, "the box app changed: update this"
    return text


def test_a_program_pybullet_crashes_on_under_the_kit_runs_and_is_told_why(tmp_path):
    result = apps.check_app(_app(tmp_path, _capsule_app()), ticks=TICKS)  # was: AppFailed, killed by signal 11
    runs = result.verdicts["runs"]
    assert runs.passed, runs.lines
    assert result.recording.ticks == TICKS
    told = [n for n in runs.notes if "getCollisionShapeData(1, -1, physicsClientId=0)" in n]
    assert len(told) == 1, runs.notes
    assert told[0].startswith("body 1 base") and "(signal 11, SIGSEGV)" in told[0] and "never made that call in the " \
        "app's process and recorded the frame without its collision shapes" in told[0], told
    capsule = next(f for f in result.recording.frames if f.body == 1)
    assert capsule.shapes == () and capsule.visuals and capsule.visuals[0][0] == "capsule"


# -- whose crash it is -----------------------------------------------------------------------------------------

#: A crash in the kit's own code: the kit's reading of the app's bodies calls a function that crashes.
KIT_CRASHES = ("import ctypes\nimport conformance.apps.bodies as _kit\n"
               "_kit.BoundClient = ctypes.string_at  # the kit's BoundClient(0) reads address 0\n")


def test_a_crash_in_the_kits_code_is_the_kits(tmp_path):
    with pytest.raises(apps.KitFailed) as err:
        apps.check_app(_app(tmp_path, KIT_CRASHES + SOURCE), ticks=TICKS)
    message = str(err.value)
    assert "the kit could not judge the program: its process was killed by signal 11 (SIGSEGV) in the kit's own code" in message
    assert "in _read_all() at conformance/apps/bodies.py:" in message, message
    assert "`p = BoundClient(client)`, the call that crashed" in message and "The program is not at fault" in message


def test_a_crash_in_the_apps_code_is_the_apps(tmp_path):
    text = "import ctypes\n" + SOURCE.replace(STEP, STEP + "    ctypes.string_at(0)\n")
    assert text.count("string_at") == 1
    with pytest.raises(apps.AppFailed) as err:
        apps.check_app(_app(tmp_path, text), ticks=TICKS)
    assert "the app's process was killed by signal 11" in str(err.value), err.value


def _dump(*frames: str, other: tuple = ()) -> str:
    """faulthandler's dump of a crash whose thread was in ``frames`` (innermost first), with another thread in ``other``."""
    lines = ["Fatal Python error: Segmentation fault", "", "Thread 0x00007f0000000001 (most recent call first):"]
    lines += [f'  File "{f}' for f in other]
    lines += ["", "Current thread 0x00007f0000000002 (most recent call first):"] + [f'  File "{f}' for f in frames]
    return "\n".join(lines + ["", "Extension modules: numpy.core._multiarray_umath (total: 1)"])


KIT = launch._KIT
STDLIB = os.path.dirname(os.__file__)


@NO_FURY
@pytest.mark.parametrize("frames, whose", [
    ([f'{KIT}/apps/bodies.py", line 232 in _read_all', f'{KIT}/apps/driver.py", line 288 in run'], "kit"),
    # Python's own functions are how the kit's code crashed, not whose code it was
    ([f'{STDLIB}/ctypes/__init__.py", line 519 in string_at', f'{KIT}/bullet/truth.py", line 70 in link_frames'], "kit"),
    # a read the guard made directly (a GUI client's) is named where it was asked for
    ([f'{KIT}/apps/guarded.py", line 88 in __call__', f'{KIT}/apps/bodies.py", line 191 in _nodes'], "kit: _nodes"),
    # in a stand-in for the app's own pyBullet call, the crash is the app's call's
    ([f'{KIT}/apps/driver.py", line 480 in step_', '/home/me/sim.py", line 30 in timer_callback'], "app"),
    # deeper than the stand-in, in the kit's reads it makes before the step, it is the kit's
    ([f'{KIT}/bullet/truth.py", line 70 in link_frames', f'{KIT}/apps/driver.py", line 480 in step_'], "kit"),
    (['/home/me/sim.py", line 30 in timer_callback', f'{KIT}/apps/takeover_vtk.py", line 60 in tick'], "app"),
    ([f'{STDLIB}/ctypes/__init__.py", line 519 in string_at', '/home/me/sim.py", line 30 in timer_callback'], "app"),
    # a library the app drew with is the app's
    (['/venv/lib/python3.11/site-packages/fury/window.py", line 9 in render', f'{KIT}/apps/driver.py", line 1 in run'], "app"),
])
def test_the_crashing_threads_innermost_frame_outside_python_says_whose_crash_it_is(frames, whose):
    site = launch.kit_crash_site(_dump(*frames, other=('/home/me/sim.py", line 1 in worker',)))
    assert (site is not None) == whose.startswith("kit"), site
    if ": " in whose:
        assert site[2] == whose.split(": ")[1], site


@NO_FURY
def test_another_threads_frames_and_a_missing_dump_are_no_kit_crash():
    assert launch.kit_crash_site(_dump('/home/me/sim.py", line 3 in f', other=(f'{KIT}/apps/bodies.py", line 1 in f',))) is None
    assert launch.kit_crash_site("Segmentation fault") is None and launch.kit_crash_site("") is None


@NO_FURY
def test_the_stand_ins_are_the_drivers_wrappers():
    """:data:`launch.STAND_INS` names the wrappers ``install_pybullet`` defines: renamed there, a crash in the
    app's own step would become the kit's."""
    import inspect

    from conformance.apps import driver

    source = inspect.getsource(driver.install_pybullet)
    assert all(f"def {name}(" in source for name in launch.STAND_INS)
    assert len(re.findall(r"(?m)^\s+def (\w+_)\(", source)) == len(launch.STAND_INS)
