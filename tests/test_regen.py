"""Regenerating goldens: by command or pytest option only, atomically, saying what changed, repeatable."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest

from conformance import cli, files
from conformance.rendering import golden

SCENE = "free_fall"


def _files(directory):
    return {p.relative_to(directory): (p.read_bytes(), p.stat().st_mtime_ns)
            for p in sorted(directory.rglob("*")) if p.is_file()}


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    directory = tmp_path_factory.mktemp("golden")
    assert cli.main(["regen", SCENE, "--golden-dir", str(directory)]) == 0
    return directory


def test_regen_makes_every_golden_frame_with_its_manifest(made):
    from conformance import scenes

    for frame in scenes.get(SCENE).frames_with_goldens():
        png, manifest = golden.paths(made, SCENE, frame)
        assert png.is_file() and manifest.is_file()


def test_regen_of_an_unchanged_scene_changes_no_byte(made, capsys, tmp_path):
    copy = tmp_path / "copy"
    import shutil

    shutil.copytree(made, copy)
    before = _files(copy)
    assert cli.main(["regen", SCENE, "--golden-dir", str(copy)]) == 0
    assert _files(copy) == before  # same bytes, and not even rewritten
    out = capsys.readouterr().out
    assert "free_fall frame 0: unchanged (byte-identical)" in out and "0 new, 0 changed, 3 unchanged" in out


def test_regen_missing_makes_only_what_is_missing(made, capsys, tmp_path):
    import shutil

    copy = tmp_path / "copy"
    shutil.copytree(made, copy)
    golden.paths(copy, SCENE, 60)[0].unlink()
    before = _files(copy)
    assert cli.main(["regen", SCENE, "--missing", "--golden-dir", str(copy)]) == 0
    after = _files(copy)
    assert {k: v for k, v in after.items() if "0060" not in str(k)} == {k: v for k, v in before.items() if "0060" not in str(k)}
    assert after[golden.paths(copy, SCENE, 60)[0].relative_to(copy)][0] == golden.paths(made, SCENE, 60)[0].read_bytes()
    assert "free_fall frame 60: new" in capsys.readouterr().out


def test_regen_failing_remakes_a_wrong_golden_and_says_by_how_much(made, capsys, tmp_path):
    import shutil

    copy = tmp_path / "copy"
    shutil.copytree(made, copy)
    png, _ = golden.paths(copy, SCENE, 120)
    from PIL import Image

    picture = np.asarray(Image.open(png)).copy()
    picture[10:20, 10:30] = (255, 0, 0)  # 200 pixels painted red
    png.write_bytes(files.encode_png(picture))
    assert cli.main(["regen", SCENE, "--failing", "--golden-dir", str(copy)]) == 0
    out = capsys.readouterr().out
    assert "free_fall frame 120: changed: 200 pixels differ" in out, out
    assert "frame 0: " not in out and "frame 60: " not in out  # the passing ones were left alone
    assert png.read_bytes() == golden.paths(made, SCENE, 120)[0].read_bytes()


def test_regen_of_an_unknown_scene_writes_nothing(tmp_path, capsys):
    assert cli.main(["regen", "no_such_scene", "--golden-dir", str(tmp_path)]) == 2
    assert "scene='no_such_scene', but should be one of" in capsys.readouterr().err
    assert not list(tmp_path.iterdir())


def _pytest(*args, cwd):
    env = {**os.environ, "PYTHONDONTWRITEBYTECODE": "1"}
    env.pop("PYTEST_XDIST_WORKER", None)
    return subprocess.run([sys.executable, "-m", "pytest", "--pyargs", "conformance", "-p", "no:cacheprovider", "-q",
                           *args], cwd=cwd, env=env, capture_output=True, text=True, timeout=600)


def test_missing_golden_fails_with_the_command_that_makes_it(tmp_path):
    empty = tmp_path / "golden"
    empty.mkdir()
    run = _pytest("-k", "test_golden_render and free_fall", "--conformance-golden-dir", str(empty), cwd=tmp_path)
    assert run.returncode == 1, run.stdout[-2000:]
    assert "no golden for scene 'free_fall' at frame 0" in run.stdout
    assert "Make it with: python -m conformance regen free_fall" in run.stdout
    assert not list(empty.iterdir()), "a check wrote a golden without being asked"


def test_regen_golden_option_under_xdist_does_not_race(tmp_path, made):
    pytest.importorskip("xdist", reason="pytest-xdist is a dev dependency; without it -n cannot be tried")
    directory = tmp_path / "golden"
    directory.mkdir()
    run = _pytest("-n", "2", "-k", "test_golden_render and (free_fall or sliding_box or crossing)",
                  "--regen-golden", "--conformance-golden-dir", str(directory), cwd=tmp_path)
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-2000:]
    assert "goldens regenerated" in run.stdout and "free_fall frame 0: new" in run.stdout
    assert not [p for p in directory.rglob("*") if p.name.endswith(".tmp")]
    for frame in (0, 60, 120):  # what the pytest option made is what the command made
        for path_made, path_here in zip(golden.paths(made, SCENE, frame), golden.paths(directory, SCENE, frame)):
            assert path_made.read_bytes() == path_here.read_bytes()


def test_physics_verdict_fails_on_a_stored_state_that_is_not_pybullets(made):
    """The physics verdict compares the live run with the manifest's state: a target moved by 2 µm in
    the stored state is a difference (1 µm tolerance), and an untouched golden is none."""
    from conformance.rendering import snapshots

    def goldens():
        return {f: golden.read(made, SCENE, f, params=dict(spec.defaults), camera=spec.camera.as_dict(),
                               size=tuple(spec.image_size)) for f in spec.frames_with_goldens()}

    from conformance import scenes

    spec = scenes.get(SCENE)
    assert all(v.difference.ok and not v.chaotic for v in snapshots.check_physics(SCENE, goldens()))
    tampered = goldens()
    tampered[60].state["targets"][0]["position"][2] += 2e-6
    verdicts = {v.frame: v for v in snapshots.check_physics(SCENE, tampered)}
    assert not verdicts[60].difference.ok and verdicts[0].difference.ok
    assert "2e-06 m (tolerance 1e-06 m)" in verdicts[60].difference.describe()
