"""The app's process (:mod:`conformance.apps.launch`): forked from a server that imported FURY once, it
behaves as ``python SCRIPT`` would where an app can tell: the kit's environment as it is now, the app's
``atexit`` handlers run at its end, its last words on stderr when it crashes; and the server adds nothing
to the kit's output."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from conformance import apps
from conformance.apps import launch

import app_sources

STEP = "    p.stepSimulation()\n"


def _app(tmp_path, extra_step: str = "", extra_top: str = ""):
    text = extra_top + app_sources.SOURCE.replace(STEP, STEP + extra_step)
    path = tmp_path / "app.py"
    path.write_text(text, encoding="utf-8")
    return path


def test_the_app_sees_the_environment_of_now_not_of_the_servers_start(tmp_path, monkeypatch):
    launch.record(_app(tmp_path), ticks=2)  # the server runs from here on
    seen = tmp_path / "seen.txt"
    monkeypatch.setenv("KIT_TEST_SET_LATER", "yes, now")
    top = f"import os\nopen({str(seen)!r}, 'w').write(os.environ.get('KIT_TEST_SET_LATER', 'unset'))\n"
    launch.record(_app(tmp_path, extra_top=top), ticks=2)
    assert seen.read_text() == "yes, now"


def test_the_apps_atexit_handlers_run_at_its_end(tmp_path):
    done = tmp_path / "atexit.txt"
    top = f"import atexit\natexit.register(lambda: open({str(done)!r}, 'w').write('ran'))\n"
    launch.record(_app(tmp_path, extra_top=top), ticks=2)
    assert done.read_text() == "ran"


def test_a_crash_is_told_with_the_apps_last_words(tmp_path):
    crash = "    import ctypes; ctypes.string_at(0) if cnt == 2 else None\n"
    with pytest.raises(apps.AppFailed) as err:
        launch.record(_app(tmp_path, extra_step=crash), ticks=5)
    message = str(err.value)
    assert "killed by signal 11" in message and "Fatal Python error: Segmentation fault" in message, message
    assert f"{(tmp_path / 'app.py').resolve()}\", line" in message and "multiprocessing" not in message, message


def test_the_server_prints_nothing(tmp_path):
    """pyBullet prints its "build time" line on import; the kit's process prints it once, and the server
    of the app processes, which imports pyBullet too, must not print a second."""
    script = "from conformance.apps import launch\nlaunch.record(__import__('sys').argv[1], ticks=2)\n"
    done = subprocess.run([sys.executable, "-c", script, str(_app(tmp_path))], capture_output=True, text=True,
                          timeout=300, env={**os.environ, "PYTHONUNBUFFERED": "1"})
    assert done.returncode == 0, done.stderr
    assert (done.stdout + done.stderr).count("pybullet build time") == 1, done.stdout + done.stderr


def test_a_script_without_a_main_guard_can_record(tmp_path):
    """multiprocessing runs the main script again in a process it starts, unless told otherwise: a user's
    script calling the kit at its top level would call it again there, and the app's process died silently."""
    script = tmp_path / "mine.py"
    script.write_text(f"from conformance.apps import launch\nrecording = launch.record({str(_app(tmp_path))!r}, ticks=2)\n"
                      "print('recorded', recording.ticks)\n", encoding="utf-8")
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0 and "recorded 2" in done.stdout, done.stdout + done.stderr
