"""A fault of the kit's own code while it drives an app is reported as the kit's, never as the app's
(issue 32, point 1): ``app`` prints ``ERROR kit`` with the kit's traceback and exits 3, and an app
that wraps its step in ``except Exception`` cannot swallow it."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from conformance import apps

import app_sources

SOURCE = app_sources.SOURCE
STEP = "    p.stepSimulation()\n"

#: Lines an app could not write by mistake: they break the kit's driver in the app's own process, as a
#: bug of the kit's would. Listing frames fails before the loop; reading them fails inside a step.
BREAK_LISTING = ("import conformance.apps.bodies as _kit\n"
                 "def _broken(clients, notes=None):\n    raise KeyError('frames')\n"
                 "_kit.frames_of = _broken\n")
BREAK_READING = ("import inspect\nimport conformance.apps.bodies as _kit\n_read = _kit.read_poses\n"
                 "def _broken(frames):\n"
                 "    if inspect.stack()[1].function == 'before_step':\n        raise KeyError('poses')\n"
                 "    return _read(frames)\n"
                 "_kit.read_poses = _broken\n")


def _app(tmp_path: Path, sabotage: str, swallow: bool = False) -> Path:
    text = sabotage + SOURCE
    if swallow:  # the app hides its own errors: the kit's must still come out as the kit's
        text = text.replace(STEP, "    try:\n        p.stepSimulation()\n    except Exception:\n        pass\n")
        assert "except Exception" in text
    path = tmp_path / "app.py"
    path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.parametrize("sabotage, swallow, where", [
    (BREAK_LISTING, False, "driving the app's loop: KeyError: 'frames'"),
    (BREAK_READING, True, "reading every frame before a step: KeyError: 'poses'"),
])
def test_a_fault_of_the_kit_is_the_kits_and_not_the_apps(tmp_path, sabotage, swallow, where):
    with pytest.raises(apps.KitFailed) as err:
        apps.check_app(_app(tmp_path, sabotage, swallow), ticks=10)
    message = str(err.value)
    assert "the kit itself failed while it ran the app, a fault of the kit and not of your program" in message
    assert where in message and "Traceback (most recent call last)" in message, message
    assert "the app raised" not in message


def test_the_app_command_says_error_kit_and_exits_3(tmp_path):
    done = subprocess.run([sys.executable, "-m", "conformance", "app", str(_app(tmp_path, BREAK_LISTING)),
                           "--perturbed", "0"], capture_output=True, text=True, timeout=600)
    assert done.returncode == 3, done.stdout + done.stderr
    assert "ERROR kit" in done.stdout and "FAIL runs" not in done.stdout, done.stdout
    assert "verdict: NONE" in done.stdout and "the kit failed, not the app" in done.stdout
