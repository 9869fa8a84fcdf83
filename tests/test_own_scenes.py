"""Your own scenes are first class: the example of ``docs/own-scenes.md``, copied out verbatim, is seen
by every command, gets its goldens beside it, is checked in the same run as the kit's scenes against
their own goldens, and names itself in every message that tells you what to run.

Everything that registers a scene runs in a child process: the registry of this process is the one
the kit's own checks were collected from, and stays as it is.
"""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

from conformance import backends, cli
from conformance.backends.display import child_environment, dies_with_this_process

DOCS = Path(__file__).resolve().parent.parent / "docs" / "own-scenes.md"
TESTS = Path(__file__).resolve().parent


def _example() -> str:
    text = DOCS.read_text(encoding="utf-8")
    return re.search(r"Save as `my_scenes.py`.*?```python\n(.*?)```", text, re.S).group(1)


def _run(where: Path, *words: str, env: dict | None = None) -> subprocess.CompletedProcess:
    environment = child_environment()
    environment.pop("CONFORMANCE_SCENES", None)
    environment.update(env or {})
    return subprocess.run([sys.executable, *words], cwd=where, capture_output=True, text=True, env=environment,
                          preexec_fn=dies_with_this_process(waited_for=True))


@pytest.fixture(scope="module")
def project(tmp_path_factory) -> Path:
    """A user's directory holding the documented ``my_scenes.py``, its goldens made by the documented command."""
    where = tmp_path_factory.mktemp("project")
    (where / "my_scenes.py").write_text(_example(), encoding="utf-8")
    made = _run(where, "-m", "conformance", "regen", "tossed_die", "--scenes", "my_scenes.py")
    assert made.returncode == 0, made.stdout + made.stderr
    return where


def test_every_command_lists_the_scene_after_the_kit_s(project):
    listed = _run(project, "-m", "conformance", "scenes", "--scenes", "my_scenes.py")
    assert listed.returncode == 0, listed.stderr
    names = [line.split()[0] for line in listed.stdout.splitlines() if line.strip()]
    assert names[-1] == "tossed_die" and "free_fall" in names
    through_environment = _run(project, "-m", "conformance", "scenes", env={"CONFORMANCE_SCENES": "my_scenes.py"})
    assert "tossed_die" in through_environment.stdout, through_environment.stderr
    without = _run(project, "-m", "conformance", "scenes")
    assert "tossed_die" not in without.stdout


def test_regen_writes_the_goldens_beside_the_scene_file_not_into_the_kit(project):
    from conformance.rendering import golden

    made = sorted(p.name for p in (project / "golden" / backends.NAME / "tossed_die").iterdir())
    assert made == ["frame-0000.json", "frame-0000.png", "frame-0060.json", "frame-0060.png",
                    "frame-0120.json", "frame-0120.png"]
    assert not (golden.default_dir() / "tossed_die").exists()


@pytest.mark.full("whole kit runs on a user's own scenes: a feature end to end, not one of CI's guarantees")
def test_one_run_checks_the_kit_s_scenes_and_yours_each_against_its_own_goldens(project):
    run = _run(project, "-m", "pytest", "--pyargs", "conformance", "-p", "no:cacheprovider", "-q",
               "--conformance-scenes", "my_scenes.py", "-k", "tossed_die or (golden and free_fall)")
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-2000:]
    verdicts = {line.split()[1]: line.split()[0] for line in run.stdout.splitlines()
                if line.startswith(("PASS ", "FAIL "))}
    assert verdicts == {"free_fall": "PASS", "tossed_die": "PASS"}, run.stdout[-2000:]


def test_pytest_takes_scenes_as_python_m_conformance_spells_it(project):
    """Issue 30, point 4: the README says "add --scenes my_scenes.py to any command"; pytest answered
    "unrecognized arguments: --scenes"."""
    run = _run(project, "-m", "pytest", "--pyargs", "conformance", "-p", "no:cacheprovider", "-q",
               "--scenes", "my_scenes.py", "-k", "test_golden_physics and tossed_die")
    assert run.returncode == 0, run.stdout[-2000:] + run.stderr[-2000:]
    assert "1 passed" in run.stdout, run.stdout[-2000:]


def test_a_missing_golden_names_the_whole_command_that_makes_it(project, tmp_path):
    run = _run(project, "-m", "pytest", "--pyargs", "conformance", "-p", "no:cacheprovider", "-q",
               "--conformance-scenes", "my_scenes.py", "-k", "test_golden_physics and tossed_die",
               "--conformance-golden-dir", str(tmp_path))
    assert run.returncode == 1
    command = re.search(r"Make it with: (.*?) \(then look", run.stdout).group(1)
    assert shlex.split(command) == ["python", "-m", "conformance", "regen", "tossed_die", "--scenes", "my_scenes.py",
                                    "--golden-dir", os.path.relpath(tmp_path, project)]
    # and the command, run as printed, makes what was missing
    made = _run(project, *shlex.split(command)[1:])
    assert made.returncode == 0, made.stderr
    assert (tmp_path / "tossed_die" / "frame-0000.png").is_file()


@pytest.mark.full("whole kit runs on a user's own scenes: a feature end to end, not one of CI's guarantees")
def test_a_failing_check_reproduces_as_printed_from_the_same_directory(project):
    wrong = {"PYTHONPATH": str(TESTS)}
    run = _run(project, "-m", "pytest", "--pyargs", "conformance", "-p", "no:cacheprovider", "-q",
               "--conformance-scenes", "my_scenes.py", "--sync", "wrong_syncs:TransposedRotation",
               "-k", "test_vertices_match_poses_every_frame and tossed_die", env=wrong)
    assert run.returncode == 1, run.stdout[-2000:]
    line = re.search(r"reproduce: (python -m conformance check tossed_die .*)", run.stdout).group(1)
    assert "--scenes my_scenes.py" in line
    replay = _run(project, *shlex.split(line)[1:], env=wrong)
    assert replay.returncode == 1 and "FAIL tossed_die" in replay.stdout, replay.stdout + replay.stderr


@pytest.mark.full("whole kit runs on a user's own scenes: a feature end to end, not one of CI's guarantees")
def test_a_changed_scene_s_physics_failure_blames_the_scene_and_its_command_runs(project, tmp_path):
    """Issue 30, point 2: it said "this is pyBullet or the platform" and printed a regen command
    without ``--scenes``, which failed with "scene='tossed_die', but should be one of: ..."."""
    import shutil

    moved = tmp_path / "moved"
    shutil.copytree(project, moved)
    source = (moved / "my_scenes.py").read_text(encoding="utf-8")
    (moved / "my_scenes.py").write_text(source.replace("position=(-0.3, 0, 0.6)", "position=(-0.3, 0, 0.65)"),
                                        encoding="utf-8")  # the user moved the die 5 cm up
    run = _run(moved, "-m", "pytest", "--pyargs", "conformance", "-p", "no:cacheprovider", "-q",
               "--conformance-scenes", "my_scenes.py", "-k", "test_golden_physics and tossed_die")
    assert run.returncode == 1, run.stdout[-2000:]
    assert "the scene changed (its populate in my_scenes.py)" in run.stdout, run.stdout[-2000:]
    assert "this is pyBullet or the platform" not in run.stdout
    command = re.search(r"make its goldens anew: (python -m conformance regen .*)", run.stdout).group(1)
    assert shlex.split(command) == ["python", "-m", "conformance", "regen", "tossed_die", "--scenes", "my_scenes.py"]
    made = _run(moved, *shlex.split(command)[1:])  # run as printed, from where the user ran
    assert made.returncode == 0, made.stdout + made.stderr
    again = _run(moved, "-m", "pytest", "--pyargs", "conformance", "-p", "no:cacheprovider", "-q",
                 "--conformance-scenes", "my_scenes.py", "-k", "test_golden_physics and tossed_die")
    assert again.returncode == 0, again.stdout[-2000:]


def test_a_golden_made_for_another_camera_is_said_once_naming_what_changed(project, tmp_path):
    """Issue 30, point 9: after a camera change the paragraph was printed twice, joined by "During
    handling of the above exception, another exception occurred", with both whole cameras."""
    import shutil

    moved = tmp_path / "camera"
    shutil.copytree(project, moved)
    source = (moved / "my_scenes.py").read_text(encoding="utf-8")
    (moved / "my_scenes.py").write_text(source.replace("Camera((0.0, -2.5, 1.2)", "Camera((0.0, -2.0, 1.2)"),
                                        encoding="utf-8")
    run = _run(moved, "-m", "pytest", "--pyargs", "conformance", "-p", "no:cacheprovider", "-q",
               "--scenes", "my_scenes.py", "-k", "test_golden_physics and tossed_die")
    assert run.returncode == 1, run.stdout[-2000:]
    assert "During handling" not in run.stdout, run.stdout[-3000:]
    # Once in the failure (the summary line under it repeats it whole where $CI is set: pytest does not
    # shorten it there).
    said = [line for line in run.stdout.splitlines() if not line.startswith("FAILED ")
            and "was made for camera position [0.0, -2.5, 1.2], but the check renders camera position [0.0, -2.0, 1.2]" in line]
    assert len(said) == 1, run.stdout[-3000:]


@pytest.mark.full("whole kit runs on a user's own scenes: a feature end to end, not one of CI's guarantees")
def test_regen_refuses_a_camera_that_cuts_a_body_off(project, tmp_path):
    """Issue 30, point 9: regen made goldens of a camera that cut the die off; only the next run's
    framing check said so, as an ``assert False`` traceback of the kit's source."""
    import shutil

    moved = tmp_path / "close"
    shutil.copytree(project, moved)
    before = {p: p.read_bytes() for p in (moved / "golden").rglob("*") if p.is_file()}
    source = (moved / "my_scenes.py").read_text(encoding="utf-8")
    (moved / "my_scenes.py").write_text(source.replace("Camera((0.0, -2.5, 1.2)", "Camera((0.0, -0.6, 0.3)"),
                                        encoding="utf-8")
    made = _run(moved, "-m", "conformance", "regen", "tossed_die", "--scenes", "my_scenes.py")
    assert made.returncode == 2, made.stdout + made.stderr
    assert "no golden made, the camera frames it badly" in made.stderr and "'die': " in made.stderr, made.stderr
    assert "Traceback" not in made.stderr
    assert {p: p.read_bytes() for p in (moved / "golden").rglob("*") if p.is_file()} == before  # nothing written
    framed = _run(moved, "-m", "pytest", "--pyargs", "conformance", "-p", "no:cacheprovider", "-q",
                  "--scenes", "my_scenes.py", "-k", "test_scene_camera_frames_every_body and tossed_die")
    assert framed.returncode == 1, framed.stdout[-2000:]
    assert "badly framed" in framed.stdout and "Move the scene's camera" in framed.stdout, framed.stdout[-2000:]
    assert "assert False" not in framed.stdout and "where False" not in framed.stdout, framed.stdout[-2000:]


@pytest.mark.parametrize("content, message", [
    (None, r"scene source 'absent.py': .*absent.py is not a file"),
    ("x = 1\n", r"defines no SceneSpec; give it one at module level"),
    ("raise RuntimeError('boom')\n", r"raised RuntimeError while being imported \(.*line 1\): boom"),
    ("import no_such_package_here\n", r"imports 'no_such_package_here', which is not installed"),
])
def test_a_bad_source_is_one_sentence_and_exit_2(tmp_path, monkeypatch, capsys, content, message):
    name = f"source_{abs(hash(content)) % 10**8}.py" if content is not None else "absent.py"
    if content is not None:
        (tmp_path / name).write_text(content, encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    status = cli.main(["scenes", "--scenes", name])
    err = capsys.readouterr().err
    assert status == 2 and re.search(message, err), err
    assert len(err.strip().splitlines()) == 1


def test_a_name_the_kit_uses_is_refused(tmp_path):
    (tmp_path / "clash.py").write_text(_example().replace('name="tossed_die"', 'name="free_fall"'), encoding="utf-8")
    run = _run(tmp_path, "-m", "conformance", "scenes", "--scenes", "clash.py")
    assert run.returncode == 2
    assert "defines scene 'free_fall', but a scene of that name is already registered (from the kit)" in run.stderr


def test_pytest_refuses_a_bad_source_before_collecting(tmp_path):
    run = _run(tmp_path, "-m", "pytest", "--pyargs", "conformance", "-p", "no:cacheprovider",
               "--conformance-scenes", "absent.py")
    assert run.returncode == 4 and "scene source 'absent.py'" in run.stderr


def test_a_printed_command_names_the_scene_file_even_when_populate_lives_in_a_helper(tmp_path):
    """Printed commands give --scenes the source that registered the scene: a scene file that imports its
    populate from a helper module is named, not the helper (which defines no SceneSpec)."""
    text = _example()
    helper, _, rest = text.partition("\ndef parameters():")
    (tmp_path / "die_helpers.py").write_text(helper, encoding="utf-8")
    (tmp_path / "my_scenes.py").write_text("from conformance.scenes import Camera, SceneSpec, Shape\n"
                                           "from die_helpers import populate\n\n\ndef parameters():" + rest,
                                           encoding="utf-8")
    probe = ("from conformance.sync import own_scenes\n"
             "own_scenes.load('my_scenes.py')\n"
             "print(own_scenes.scene_arguments('tossed_die'))\n")
    done = subprocess.run([sys.executable, "-c", probe], cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.strip().splitlines()[-1] == "['--scenes', 'my_scenes.py']", done.stdout


def test_a_scene_from_a_module_is_named_by_the_module_and_its_goldens_sit_beside_its_file(tmp_path):
    """A scene source given as a module's name is printed as that name (re-imported as a file, a package's
    module would lose its relative imports), and its goldens live beside the module's file."""
    package = tmp_path / "mypkg"
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "scenes.py").write_text(_example(), encoding="utf-8")
    probe = ("from conformance.sync import own_scenes\n"
             "own_scenes.load('mypkg.scenes')\n"
             "print(own_scenes.scene_arguments('tossed_die'))\n"
             "print(own_scenes.golden_dir('tossed_die').relative_to(__import__('os').getcwd()))\n")
    env = {**os.environ, "PYTHONPATH": str(tmp_path)}
    done = subprocess.run([sys.executable, "-c", probe], cwd=tmp_path, env=env, capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    arguments, goldens = done.stdout.strip().splitlines()[-2:]
    assert arguments == "['--scenes', 'mypkg.scenes']", done.stdout
    assert goldens == f"mypkg/golden/{backends.NAME}", done.stdout
