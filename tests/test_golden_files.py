"""Golden files: bad input gets one clear error and changes nothing; writing is atomic and repeatable."""

from __future__ import annotations

import json
import os

import numpy as np
import pytest

from conformance.errors import GoldenError, GoldenMissing, GoldenUnreadable
from conformance import files
from conformance.rendering import golden

SCENE, FRAME, SIZE = "free_fall", 60, (12, 8)
PARAMS = {"height": 3.0, "orientation": (0.3, 0.2, 0.1, 0.927)}
CAMERA = {"position": [1.0, 2.0, 3.0], "focal_point": [0.0, 0.0, 0.0], "view_up": [0.0, 0.0, 1.0],
          "view_angle": 30.0, "clipping_range": [0.1, 100.0]}
REGEN = "python -m conformance regen free_fall"


def _picture(seed=0):
    return np.random.default_rng(seed).integers(0, 256, (SIZE[1], SIZE[0], 3), dtype=np.uint8)


def _manifest(**changes):
    manifest = {"format": golden.FORMAT, "scene": SCENE, "params": PARAMS, "frame": FRAME, "camera": CAMERA,
                "size": list(SIZE), "sync": "reference", "renderer": {"backend": "vtk"}, "versions": {},
                "state": {"bodies": [{"body": 0, "position": [0.1, 0.2, 0.30000000000000004]}], "targets": []}}
    manifest.update(changes)
    return manifest


@pytest.fixture
def stored(tmp_path):
    golden.write(tmp_path, SCENE, FRAME, _picture(), _manifest())
    return tmp_path


def _read(directory):
    return golden.read(directory, SCENE, FRAME, params=PARAMS, camera=CAMERA, size=SIZE)


def _snapshot(directory):
    return {p.relative_to(directory): p.read_bytes() for p in sorted(directory.rglob("*")) if p.is_file()}


def test_round_trip_is_exact(stored):
    back = _read(stored)
    assert np.array_equal(back.image, _picture())
    assert back.state["bodies"][0]["position"][2] == 0.30000000000000004  # floats round-trip bit for bit


def test_rewriting_the_same_golden_changes_no_byte_and_touches_no_file(stored):
    png, manifest = golden.paths(stored, SCENE, FRAME)
    before = _snapshot(stored), png.stat().st_mtime_ns, manifest.stat().st_mtime_ns
    assert golden.write(stored, SCENE, FRAME, _picture(), _manifest()) is False
    assert (_snapshot(stored), png.stat().st_mtime_ns, manifest.stat().st_mtime_ns) == before
    assert golden.write(stored, SCENE, FRAME, _picture(seed=1), _manifest()) is True


def test_png_bytes_depend_only_on_the_pixels():
    assert files.encode_png(_picture()) == files.encode_png(_picture().copy())
    assert b"tIME" not in files.encode_png(_picture()) and b"tEXt" not in files.encode_png(_picture())


def test_files_are_ordinary_readable_files(stored):
    png, manifest = golden.paths(stored, SCENE, FRAME)
    for path in (png, manifest):
        assert path.stat().st_mode & 0o044 == 0o044, f"{path} is not readable by others (mkstemp's 0600 kept?)"


def test_a_failed_write_leaves_the_old_golden_whole_and_no_temporary_file(stored, monkeypatch):
    before = _snapshot(stored)

    def crash(src, dst):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(files.os, "replace", crash)
    with pytest.raises(OSError, match="No space left"):
        golden.write(stored, SCENE, FRAME, _picture(seed=2), _manifest())
    assert _snapshot(stored) == before
    assert not [p for p in stored.rglob("*") if p.name.endswith(".tmp")]


def test_missing_golden_names_the_file_and_the_command_that_makes_it(tmp_path):
    with pytest.raises(GoldenMissing, match=rf"no golden for scene 'free_fall' at frame 60: .*frame-0060.png .*{REGEN}"):
        _read(tmp_path)


def test_missing_manifest_is_missing(stored):
    golden.paths(stored, SCENE, FRAME)[1].unlink()
    with pytest.raises(GoldenMissing, match=r"frame-0060.json does not exist"):
        _read(stored)


def _damage(directory, which, data: bytes):
    path = golden.paths(directory, SCENE, FRAME)[which]
    path.write_bytes(data)


@pytest.mark.parametrize("damage, message", [
    (lambda d: _damage(d, 0, golden.paths(d, SCENE, FRAME)[0].read_bytes()[:60]), r"is damaged or truncated"),
    (lambda d: _damage(d, 0, b"GIF89a not a png at all"), r"is not a PNG \(its first bytes are b'GIF89a n'\)"),
    (lambda d: _damage(d, 0, files.encode_png(np.zeros((9, 12, 3), np.uint8))), r"is 12x9 pixels, but the scene renders 12x8"),
    (lambda d: _damage(d, 1, b"{ not json"), r"has a manifest that is not valid JSON"),
    (lambda d: _damage(d, 1, b"[]"), r"has a manifest without format, scene"),
    (lambda d: _damage(d, 1, json.dumps({k: v for k, v in _manifest().items() if k != "state"}).encode()),
     r"has a manifest without state"),
    (lambda d: _damage(d, 1, golden.encode_manifest(_manifest(format=99))), r"manifest format 99, but this kit reads format 1"),
    (lambda d: _damage(d, 1, golden.encode_manifest(_manifest(params={**PARAMS, "height": 5.0}))),
     r"was made for params height 5.0, but the check renders params height 3.0;"),  # the entries that differ only
    (lambda d: _damage(d, 1, golden.encode_manifest(_manifest(frame=61))), r"was made for frame 61, but the check renders frame 60"),
    (lambda d: _damage(d, 1, golden.encode_manifest(_manifest(camera={**CAMERA, "view_angle": 40.0}))),
     r"was made for camera view_angle 40.0, but the check renders camera view_angle 30.0;"),
], ids=["truncated", "not-png", "wrong-size", "manifest-not-json", "manifest-not-object", "manifest-without-state",
        "manifest-format", "other-params", "other-frame", "other-camera"])
def test_bad_golden_is_one_clear_error_and_changes_nothing(stored, damage, message):
    damage(stored)
    before = _snapshot(stored)
    with pytest.raises(GoldenUnreadable, match=message) as caught:
        _read(stored)
    text = str(caught.value)
    assert "\n" not in text and REGEN in text and "nothing was written" in text, text
    assert _snapshot(stored) == before


def test_golden_errors_are_conformance_errors():
    from conformance.errors import ConformanceError

    assert issubclass(GoldenMissing, GoldenError) and issubclass(GoldenUnreadable, GoldenError)
    assert issubclass(GoldenError, ConformanceError)


def test_unreadable_file_is_reported_not_raised_as_os_error(stored):
    png = golden.paths(stored, SCENE, FRAME)[0]
    if os.geteuid() == 0:  # root reads anything: make the PNG a directory instead
        png.unlink()
        png.mkdir()
    else:
        png.chmod(0)
    with pytest.raises(GoldenUnreadable, match="cannot be read"):
        _read(stored)


def test_a_damaged_old_golden_is_no_picture_to_compare_a_remade_one_with(stored):
    """``regen`` compares a remade golden with the stored picture when the old one no longer fits the
    scene; a stored PNG that does not decode is no picture (None), not an error of the kit's own."""
    assert golden.picture_of(stored, SCENE, FRAME).shape == (SIZE[1], SIZE[0], 3)
    _damage(stored, 0, golden.paths(stored, SCENE, FRAME)[0].read_bytes()[:60])
    assert golden.picture_of(stored, SCENE, FRAME) is None
    assert golden.picture_of(stored, "no_such_scene", FRAME) is None
