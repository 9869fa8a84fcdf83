"""App mode end to end, on the installed FURY: ``python -m conformance app`` and the pytest checks run a
small app unmodified in its own process, accept it, and reject copies with one mistake each, naming
it; apps the kit cannot drive, that raise, crash or hang get one paragraph each."""

from __future__ import annotations

import subprocess
import sys
import shlex
import textwrap
from pathlib import Path

import pybullet
import pytest

from conformance import apps, backends
from conformance.apps import driver, launch

import app_sources

APP, SOURCE = app_sources.BOX, app_sources.SOURCE
STEP = "    p.stepSimulation()\n"


def _copy(tmp_path, text, name="app.py") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def _cli(*args):
    return subprocess.run([sys.executable, "-m", "conformance", "app", *map(str, args)], capture_output=True, text=True,
                          timeout=600)


@pytest.mark.full("whole app runs in processes of their own; CI judges app mode end to end on every example app (test_examples)")
def test_a_right_app_passes_every_check_and_its_perturbed_runs():
    done = _cli(APP, "--perturbed", "1")
    assert done.returncode == 0, done.stdout + done.stderr
    assert "verdict: PASS" in done.stdout and "PASS perturbed" in done.stdout


def test_an_app_drawing_its_box_longer_than_its_body_fails_only_the_picture(tmp_path):
    """Every vertex follows the body rigidly, so the vertex checks pass; the box is drawn 0.6 m long
    where pyBullet simulates 0.4 m, which only the picture against pyBullet's own shows."""
    longer = SOURCE.replace("scales=np.array([[0.2, 0.4, 0.2]])", "scales=np.array([[0.2, 0.6, 0.2]])")
    assert longer != SOURCE
    result = apps.check_app(_copy(tmp_path, longer), ticks=51)
    assert [name for name, v in result.verdicts.items() if not v.passed] == ["pictured"], result.verdicts
    assert "not-its-shape" in result.verdicts["pictured"].diagnoses, result.verdicts["pictured"].message()


def test_an_app_on_a_client_of_its_own_through_bullet_client_runs_as_it_would_alone(tmp_path):
    """BulletClient binds its client id only to what ``inspect.isbuiltin`` calls a builtin; the kit's
    wrapped ``stepSimulation`` must pass for one, or the app steps the empty client 0 and its box
    hangs in the air under the kit while it falls without it."""
    result = apps.check_app(_copy(tmp_path, app_sources.on_a_client_of_its_own()), ticks=20)
    recording = result.recording
    assert [(f.client, f.body, f.link) for f in recording.frames] == [(1, 0, -1)]
    assert list(recording.steps[1:]) == [1] * 20
    fallen = recording.positions[0, 0, 2] - recording.positions[-1, 0, 2]
    assert fallen > 0.02, f"the box fell {fallen:.4f} m in 20 ticks under the kit, but should fall as it does alone"
    assert all(v.passed for v in result.verdicts.values()), {k: v.message() for k, v in result.verdicts.items() if not v.passed}


def test_an_app_that_opens_pybullets_window_is_run_without_a_display(tmp_path, monkeypatch):
    """``p.connect(p.GUI)`` (the Quickstart's first line) needs an X display: FURY 0.12's app process has
    the kit's Xvfb, so pyBullet's window opens there and the program runs unchanged; FURY 2's has none,
    and pyBullet would end the process ("cannot connect to X server"), so the kit connects it with
    ``p.DIRECT`` and says so under ``runs``."""
    monkeypatch.delenv("DISPLAY", raising=False)
    windowed = SOURCE.replace("p.connect(p.DIRECT)", "p.connect(p.GUI)")
    assert windowed != SOURCE
    result = apps.check_app(_copy(tmp_path, windowed), ticks=10)
    assert all(v.passed for v in result.verdicts.values()), {k: v.message() for k, v in result.verdicts.items() if not v.passed}
    notes = result.verdicts["runs"].notes
    if backends.NAME == "vtk":
        assert notes == [], notes
    else:
        assert len(notes) == 1 and notes[0].startswith("client 0: the app connects with p.GUI") and "p.DIRECT" in notes[0], notes


@pytest.mark.parametrize("args, kwargs, display, passed_on", [
    ((pybullet.GUI,), {}, None, ((pybullet.DIRECT,), {})),
    ((), {"method": pybullet.GUI, "options": "--width=64"}, None, ((pybullet.DIRECT,), {"options": "--width=64"})),
    ((pybullet.GUI_SERVER,), {}, None, ((pybullet.DIRECT,), {})),
    ((pybullet.GUI,), {}, ":0", ((pybullet.GUI,), {})),
    ((pybullet.DIRECT,), {}, None, ((pybullet.DIRECT,), {})),
    ((pybullet.SHARED_MEMORY,), {"key": 7}, None, ((pybullet.SHARED_MEMORY,), {"key": 7})),
])
def test_only_a_window_with_no_display_is_connected_headless(args, kwargs, display, passed_on):
    new_args, new_kwargs, note = driver.headless(args, kwargs, display)
    assert (new_args, new_kwargs) == passed_on
    assert bool(note) == (passed_on != (args, kwargs))


def test_an_app_that_syncs_before_it_steps_is_one_step_late(tmp_path):
    late = SOURCE.replace(STEP, "").replace("    showm.render()\n", "    showm.render()\n" + STEP)
    assert late != SOURCE
    done = _cli(_copy(tmp_path, late), "--perturbed", "0")
    assert done.returncode == 1
    assert "FAIL attached" in done.stdout and "previous step" in done.stdout
    assert "reproduce: python -m conformance app" in done.stdout


def test_an_app_that_never_moves_its_actor_leaves_its_body_undrawn(tmp_path):
    setter = "ball_actor.SetUserMatrix(u)" if backends.NAME == "vtk" else "box.local.rotation = orn"
    never = SOURCE.replace(setter, "pass")
    if backends.NAME == "pygfx":
        never = never.replace("box.local.position = pos", "pass")
    result = apps.check_app(_copy(tmp_path, never), ticks=30)
    assert not result.verdicts["drawn"].passed
    assert "body 0 base" in result.verdicts["drawn"].message()


@pytest.mark.parametrize("change, needle", [
    (lambda s: s.replace("showm.start()", "pass").replace("p.disconnect()", "pass"),
     "without registering a per-frame function"),
    (lambda s: s.replace("scene = window.Scene()", "scene = window.Scene()\nraise ValueError('no scene today')"),
     "the app raised before its loop ran: ValueError: no scene today"),
    (lambda s: s.replace(STEP, STEP + "    import os; os._exit(7) if cnt == 3 else None\n"),
     "exited with status 7"),
    (lambda s: s.replace(STEP, STEP + "    import ctypes; ctypes.string_at(0) if cnt == 3 else None\n"),
     "killed by signal"),
])
def test_an_app_the_kit_cannot_run_gets_one_paragraph(tmp_path, change, needle):
    text = change(SOURCE)
    assert text != SOURCE
    if "without registering" in needle:  # no callback at all: the app only builds its scene
        text = text.replace("showm.add_timer_callback(True, 1, timer_callback)", "pass").replace(
            'showm.register_callback(timer_callback, 1 / 240, True, "physics")', "pass") + "\nshowm.start()\n"
    with pytest.raises(apps.AppFailed) as err:
        apps.check_app(_copy(tmp_path, text), ticks=10)
    message = str(err.value)
    assert needle in message, message
    assert "Traceback (most recent call last)" not in message.split("\n")[0]


@pytest.mark.full("waits out an app's 20 s timeout: robustness, not discrimination")
def test_an_app_that_hangs_is_stopped_at_the_timeout(tmp_path):
    hangs = SOURCE.replace(STEP, STEP + "    import time; time.sleep(600) if cnt == 2 else None\n")
    with pytest.raises(apps.AppFailed, match="did not finish 10 ticks within 20 s"):
        launch.record(_copy(tmp_path, hangs), ticks=10, timeout=20)


def test_an_app_raising_in_its_callback_fails_runs(tmp_path):
    raises = SOURCE.replace(STEP, STEP + "    if cnt == 4:\n        raise RuntimeError('lost the body')\n")
    result = apps.check_app(_copy(tmp_path, raises), ticks=20)
    assert not result.verdicts["runs"].passed
    assert "the app raised at tick 5: RuntimeError: lost the body" in result.verdicts["runs"].message()


@pytest.mark.full("whole app runs in processes of their own; CI judges app mode end to end on every example app (test_examples)")
def test_apps_in_the_ini_are_checked_one_id_per_check(pytester):
    pytester.makefile(".py", app=SOURCE)
    # The app's mapping beside it is matched by the glob, and is not an app.
    actor, body = ("ball_actor", "ball") if backends.NAME == "vtk" else ("box", "body")
    (pytester.path / "app.mapping.py").write_text(f"from conformance.apps.mapping import Draws\n\n"
                                                  f"def mapping(app):\n    return [Draws(app.{actor}, app.{body})]\n")
    pytester.makeini(textwrap.dedent("""\
        [pytest]
        conformance_apps = *.py
        conformance_app_ticks = 20
    """))
    result = pytester.runpytest_subprocess("--pyargs", "conformance.test_apps", "-p", "no:cacheprovider",
                                           "--hypothesis-profile", "triage", "-q")
    result.assert_outcomes(passed=len(apps.CHECKS) + 1)
    result.stdout.fnmatch_lines(["*PASS  app:app.py*"])


def test_the_header_of_a_run_with_apps_says_the_apps_are_judged_on_their_own_code(pytester):
    """Issue 30, point 10: a run checking an app said only "sync 'reference'" in its header."""
    pytester.makefile(".py", app=SOURCE)
    result = pytester.runpytest_subprocess("--pyargs", "conformance.test_apps", "-p", "no:cacheprovider",
                                           "--conformance-app", "app.py", "--collect-only")
    result.stdout.fnmatch_lines(["conformance: sync 'reference' in the scenes' checks; apps (their own code): app.py; *"])


def test_a_missing_app_is_a_usage_error(pytester):
    result = pytester.runpytest_subprocess("--pyargs", "conformance.test_apps", "--conformance-app", "nowhere.py")
    assert result.ret == pytest.ExitCode.USAGE_ERROR
    result.stderr.fnmatch_lines(["*--conformance-app='nowhere.py': no such file*"])


SPHERES = Path(__file__).parent / "apps" / "spheres_pygfx.py"
ANNOUNCE_NORMALS = "        balls.geometry.normals.update_range(i * sec, sec)\n"
ANNOUNCE_POSITIONS = "        balls.geometry.positions.update_range(i * sec, sec)\n"


@pytest.mark.skipif(backends.NAME != "pygfx", reason="pygfx uploads each buffer's announced ranges alone; FURY 0.12's "
                    "one Modified() re-uploads all of the geometry, which the box app's copies cover")
@pytest.mark.parametrize("change, needle", [
    (lambda s: s, None),
    (lambda s: s.replace(ANNOUNCE_NORMALS, ""), r"at tick 1 its normals changed at vertices 0–\d+ \(\d+ of them\), with nothing announced"),
    (lambda s: s.replace(ANNOUNCE_POSITIONS, "").replace(ANNOUNCE_NORMALS, ANNOUNCE_NORMALS + "    balls.geometry.positions"
                                                        ".update_range(i * sec, sec)\n"),
     r"at tick 1 its positions changed at vertices 0–\d+ \(\d+ of them\), outside every range announced"),
])
@pytest.mark.full("whole app runs in processes of their own; CI judges app mode end to end on every example app (test_examples)")
def test_every_buffer_and_range_an_app_changes_is_announced(tmp_path, change, needle):
    import re

    text = change(SPHERES.read_text(encoding="utf-8"))
    verdict = apps.check_app(_copy(tmp_path, text), ticks=20).verdicts["announced"]
    if needle is None:
        assert verdict.passed, verdict.message()
    else:
        assert not verdict.passed and re.search(needle, verdict.message()), verdict.message()


def test_an_app_s_reproduce_line_keeps_its_tick_function():
    """A printed command runs as printed: an app whose loop is its own needs its --tick again."""
    from conformance.apps import reproduce_command

    words = shlex.split(reproduce_command("my app.py", 30, [{"kind": "kick"}], "on_frame"))
    assert words[:4] == ["python", "-m", "conformance", "app"] and words[4] == "my app.py"
    assert words[words.index("--tick") + 1] == "on_frame" and words[words.index("--ticks") + 1] == "30"
    assert "--tick" not in shlex.split(reproduce_command("app.py", 30))


@pytest.mark.parametrize("drawn, diagnosis", [("at the end", ""), ("before its own move", "before-own-move"),
                                              ("before the step", "previous-step")])
def test_a_playback_drawn_a_tick_behind_is_told_its_mistake_by_a_run_of_the_kits_moves(tmp_path, drawn, diagnosis):
    """Issue 48: a playback drawn before its own reset and one drawn before the step draw the same vertices on
    their own run (the judge names the tie); the kit's short run with its moves after the step tells them apart,
    and the report names the one made and says how it was told. A right playback passes and gets no such run."""
    from conformance.apps.verdict import lead

    result = apps.check_app(_copy(tmp_path, app_sources.played_back(drawn)), ticks=12)
    named = {d for v in result.verdicts.values() for d in v.diagnoses}
    assert result.passed == (not diagnosis), {c: v.message() for c, v in result.verdicts.items()}
    if diagnosis:
        alone = {d for v in apps.judge(result.recording).values() for d in v.diagnoses}
        assert "late-or-own-move" in alone, alone  # the own run alone cannot tell
        assert lead(named) == diagnosis and "late-or-own-move" not in named, named
        notes = [n for v in result.verdicts.values() for n in v.notes if "told apart" in n]
        assert notes and notes[0].startswith(f"{diagnosis}, not "), notes
