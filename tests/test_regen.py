"""Regenerating goldens: by command or pytest option only, atomically, saying what changed, repeatable."""

from __future__ import annotations

import json
import os
import re
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


def test_regen_after_a_camera_change_says_how_many_pixels_changed(copy, capsys):
    """Issue 30, point 1: a golden made for another camera cannot be read as the scene's, so it was
    replaced without being compared and regen said "pixels identical" (73,625 of 172,800 differed)."""
    from PIL import Image

    png, manifest_path = golden.paths(copy, SCENE, 120)
    manifest = json.loads(manifest_path.read_text())
    manifest["camera"]["position"] = [8.0, -6.0, 2.5]  # made with another camera
    manifest_path.write_text(json.dumps(manifest))
    picture = np.asarray(Image.open(png)).copy()
    picture[10:20, 10:30] = (255, 0, 0)  # and so another picture: 200 pixels
    png.write_bytes(files.encode_png(picture))
    assert cli.main(["regen", SCENE, "--golden-dir", str(copy)]) == 0
    out = capsys.readouterr().out
    assert "free_fall frame 120: changed: 200 pixels differ" in out, out
    assert "the old golden did not fit the scene: frame-0120.json was made for camera" in out, out
    assert "pixels identical" not in out, out


def _bumped(value, by):
    """Every float of a state moved by ``by`` (ids, names and the shape kept): another CPU's last bits."""
    if type(value) is float:
        return by(value)
    if isinstance(value, list):
        return [_bumped(v, by) for v in value]
    if isinstance(value, dict):
        return {k: _bumped(v, by) for k, v in value.items()}
    return value


def _one_ulp(x):
    return float(np.nextafter(x, np.inf))


@pytest.fixture
def copy(made, tmp_path):
    import shutil

    shutil.copytree(made, tmp_path / "copy")
    return tmp_path / "copy"


def _regen_from(monkeypatch, directory, alter):
    """``regen`` of ``directory`` from goldens made as usual, each ``(frame, image, manifest)`` passed
    through ``alter`` first: another machine's run, made here."""
    from conformance.rendering import snapshots

    real = snapshots.make
    monkeypatch.setattr(snapshots, "make", lambda name: [alter(*made) for made in real(name)])
    assert cli.main(["regen", SCENE, "--golden-dir", str(directory)]) == 0


def _noisy(frame, image, manifest, by=_one_ulp):
    return frame, image, {**manifest, "state": _bumped(manifest["state"], by)}


@pytest.mark.parametrize("by", [_one_ulp, lambda x: x * (1 + 1e-15)], ids=["nextafter", "times-1+1e-15"])
def test_regen_keeps_goldens_whose_state_differs_only_by_float_noise(copy, monkeypatch, capsys, by):
    """A state whose every float moved in its last bits, and the same pictures: no file is touched,
    and each golden says it was kept, by how much and within what bound."""
    before = _files(copy)
    manifest = golden.paths(copy, SCENE, 60)[1]
    noisy = _noisy(60, None, json.loads(manifest.read_text()), by)[2]
    assert golden.encode_manifest(noisy) != manifest.read_bytes()  # writing it would change bytes
    _regen_from(monkeypatch, copy, lambda frame, image, made: _noisy(frame, image, made, by))
    assert _files(copy) == before  # same bytes and mtimes: not rewritten
    out = capsys.readouterr().out
    assert re.search(r"free_fall frame 60: kept, not rewritten: same pixels, and the state differs only by float "
                     r"noise \(largest difference [0-9.e-]+ at \w+\[\d+\]\.\w+\[\d\], [0-9.e+-]+ % of the physics tolerance \(bound 10 %\)\)", out), out
    assert "0 new, 0 changed, 0 unchanged, 3 kept with float noise" in out, out


@pytest.mark.parametrize("factor, status", [(0.5, "kept"), (2.0, "changed")])
def test_a_state_change_beyond_the_float_noise_bound_is_written(copy, monkeypatch, capsys, factor, status):
    """One target moved by half the bound is kept; by twice the bound, its manifest is written and
    the physics difference reported (the picture is the same)."""
    from conformance.bullet import state

    def moved(frame, image, made):
        made = json.loads(json.dumps(made))
        if frame == 60:
            made["state"]["targets"][0]["position"][2] += factor * state.FLOAT_NOISE
        return frame, image, made

    before = _files(copy)
    _regen_from(monkeypatch, copy, moved)
    out = capsys.readouterr().out
    assert f"free_fall frame 60: {status}" in out and "frame 0: unchanged" in out, out
    manifest = golden.paths(copy, SCENE, 60)[1]
    assert (_files(copy) == before) == (status == "kept")
    if status == "changed":
        assert ("pixels identical; physics: largest difference at 'body': 2e-07 m" in out
                and "; state beyond float noise: largest difference 2e-07 at targets[0].position[2], 20 % of the physics tolerance (bound 10 %)" in out), out
        stored = json.loads(manifest.read_text())["state"]["targets"][0]["position"][2]
        assert stored == json.loads(before[manifest.relative_to(copy)][0])["state"]["targets"][0]["position"][2] + 2e-7


def test_a_changed_picture_is_written_even_when_the_state_is_only_noise(copy, monkeypatch, capsys):
    def repainted(frame, image, made):
        if frame == 120:
            image = image.copy()
            image[0, 0] = 255 - image[0, 0]
        return _noisy(frame, image, made)

    before = _files(copy)
    _regen_from(monkeypatch, copy, repainted)
    out = capsys.readouterr().out
    assert "free_fall frame 120: changed: 1 pixels differ" in out and "frame 60: kept, not rewritten: " in out, out
    after = _files(copy)
    for path in golden.paths(copy, SCENE, 120):  # both files: the picture and its state, as made
        assert after[path.relative_to(copy)][0] != before[path.relative_to(copy)][0]
    assert {k: v for k, v in after.items() if "0120" not in str(k)} == {k: v for k, v in before.items() if "0120" not in str(k)}


@pytest.mark.parametrize("key, value", [("versions", {"pybullet": "9.9.9"}), ("renderer", {"backend": "other"}),
                                        ("sync", "someone_else"), ("camera", {"view_angle": 31.0})])
def test_any_other_manifest_difference_is_written_with_the_noise(copy, monkeypatch, capsys, key, value):
    """Float noise keeps a golden only when it is the sole difference: another version, renderer,
    sync or camera in the manifest is written as before (with the noisy state)."""
    def other(frame, image, made):
        frame, image, made = _noisy(frame, image, made)
        return frame, image, {**made, key: value}

    _regen_from(monkeypatch, copy, other)
    out = capsys.readouterr().out
    assert "0 new, 3 changed, 0 unchanged, 0 kept" in out, out
    assert json.loads(golden.paths(copy, SCENE, 0)[1].read_text())[key] == value


def test_float_noise_is_the_largest_float_difference_of_states_alike_in_all_else():
    from conformance.bullet import state

    old = {"bodies": [{"body": 1, "joints": [], "position": [0.25, -0.0, 3.0]}], "targets": [{"name": "box", "position": [1.0]}]}
    assert state.float_noise(old, old) == state.FloatNoise(0.0, "")
    noise = state.float_noise(_bumped(old, lambda x: x + 1e-12 if x == 3.0 else x), old)
    assert noise.where == "bodies[0].position[2]" and noise.largest == pytest.approx(1e-12) and noise.is_noise
    assert not state.float_noise(_bumped(old, lambda x: x + 2 * state.FLOAT_NOISE), old).is_noise
    assert state.float_noise(_bumped(old, abs), old).largest == 0.0  # -0.0 and 0.0: other bytes, no distance
    for other in ({**old, "targets": []}, {**old, "targets": [{"name": "lid", "position": [1.0]}]},
                  {**old, "bodies": [{"body": 2, "joints": [], "position": [0.25, -0.0, 3.0]}]},
                  {**old, "bodies": [{"body": 1, "joints": [], "position": [0.25, 0, 3.0]}]},
                  {**old, "bodies": [{"body": 1, "joints": [], "position": [0.25, float("nan"), 3.0]}]}):
        assert state.float_noise(other, old) is None, other  # not float noise: something else changed


@pytest.mark.parametrize("field, change, noise", [
    ("position", 5e-8, True), ("position", 2e-7, False),                 # against 1 µm
    ("orientation", 4e-7, True), ("orientation", 6e-7, False),           # twice it, against 1e-5 rad
    ("angular_velocity", 1e-4, True), ("angular_velocity", 1e-3, False),  # over one 1/240 s step
    ("linear_velocity", 1e-5, True), ("linear_velocity", 1e-4, False)])
def test_each_float_counts_against_the_tolerance_of_what_it_is(field, change, noise):
    from conformance.bullet import state

    old = {"bodies": [{"body": 1, field: [0.5, 0.25, 0.125]}]}
    new = {"bodies": [{"body": 1, field: [0.5, 0.25 + change, 0.125]}]}
    found = state.float_noise(new, old)
    assert found.is_noise is noise, f"{field} moved by {change}: {found.describe()}, but should {'' if noise else 'not '}be noise"


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


@pytest.mark.full("a whole regeneration under -n 2: a race of the tool, not one of CI's guarantees")
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
