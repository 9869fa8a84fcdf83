"""The golden physics replay shared by the processes of one session (``snapshots.SHARED_STATES``): what one
process stepped another reads back, the same to the last bit; a damaged file is stepped again and
rewritten whole; a scene defined otherwise under the same name is another file."""

from __future__ import annotations

import dataclasses

import pytest

from conformance import scenes
from conformance.rendering import snapshots

SCENE = "free_fall"
FRAMES = (0, 60, 120)


@pytest.fixture
def shared(tmp_path, monkeypatch):
    monkeypatch.setenv(snapshots.SHARED_STATES, str(tmp_path))
    return tmp_path


def _stepped() -> dict:
    """The states as a process without a shared directory steps them."""
    return snapshots.live_states.__wrapped__(SCENE, FRAMES)


def test_states_stepped_once_are_read_back_bit_for_bit(shared, monkeypatch):
    monkeypatch.delenv(snapshots.SHARED_STATES)
    alone = _stepped()
    monkeypatch.setenv(snapshots.SHARED_STATES, str(shared))
    assert _stepped() == alone
    assert len(list(shared.glob(f"{SCENE}-*.json"))) == 1

    def no_stepping(*args, **kwargs):
        raise AssertionError("the shared states were stepped again")

    monkeypatch.setattr(scenes, "build", no_stepping)
    assert _stepped() == alone


def test_a_damaged_file_is_stepped_again_and_rewritten_whole(shared, monkeypatch):
    alone = _stepped()
    (path,) = shared.glob(f"{SCENE}-*.json")
    path.write_bytes(path.read_bytes()[:100])
    assert _stepped() == alone
    monkeypatch.setattr(scenes, "build", lambda *a, **k: pytest.fail("stepped a third time"))
    assert _stepped() == alone


def test_a_scene_defined_otherwise_is_another_file(shared, monkeypatch):
    first = snapshots._shared_file(SCENE, FRAMES)
    spec = scenes.get(SCENE)
    monkeypatch.setattr(scenes, "get", lambda name: dataclasses.replace(spec, gravity=(0.0, 0.0, -9.81)))
    assert snapshots._shared_file(SCENE, FRAMES) != first
    assert snapshots._shared_file(SCENE, FRAMES[:2]) not in (first, snapshots._shared_file(SCENE, FRAMES))


def test_nothing_is_shared_without_the_variable(monkeypatch, tmp_path):
    monkeypatch.delenv(snapshots.SHARED_STATES, raising=False)
    assert snapshots._shared_file(SCENE, FRAMES) is None
