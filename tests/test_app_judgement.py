"""The app judgement (conformance.apps.judge) on recordings made by hand: each check passes a right
drawing and fails, with the right diagnosis, on a drawing with one known mistake."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from app_recordings import CORNERS, box_frame, draw, motion, recording, track
from conformance.apps import judge


def _failing(verdicts):
    return {name for name, v in verdicts.items() if not v.passed}


def test_a_right_drawing_passes_every_check():
    pos, orn = motion()
    verdicts = judge(recording([box_frame()], [(pos, orn)], [track(draw(pos, orn))]))
    assert _failing(verdicts) == set(), {k: v.message() for k, v in verdicts.items()}


def test_float32_storage_is_within_the_allowance():
    pos, orn = motion()
    drawn = draw(pos, orn).astype(np.float32).astype(np.float64)
    assert _failing(judge(recording([box_frame()], [(pos, orn)], [track(drawn)]))) == set()


@pytest.mark.parametrize("mistake, check, diagnosis", [
    ("previous-step", "attached", "previous-step"),
    ("conjugate", "attached", "conjugate"),
    ("wxyz", "attached", "wxyz"),
    ("scalar-first", "attached", "scalar-first"),
    ("translation-only", "attached", "translation-only"),
    ("never-moved", "drawn", "never-moved"),
    ("unannounced", "announced", "unannounced"),
    ("jitter", "attached", None),
])
def test_a_known_mistake_fails_with_its_diagnosis(mistake, check, diagnosis):
    pos, orn = motion()
    changed = announced = None
    if mistake == "previous-step":
        drawn = draw(np.concatenate([pos[:1], pos[:-1]]), np.concatenate([orn[:1], orn[:-1]]))
    elif mistake == "conjugate":
        drawn = draw(pos, Rotation.from_quat(orn).inv().as_quat())
    elif mistake == "wxyz":
        drawn = draw(pos, np.roll(orn, 1, axis=1))
    elif mistake == "scalar-first":
        drawn = draw(pos, Rotation.from_quat(orn, scalar_first=True).as_quat())
    elif mistake == "translation-only":
        drawn = draw(pos, np.tile(orn[:1], (len(orn), 1)))
    elif mistake == "never-moved":
        drawn = draw(np.tile(pos[:1], (len(pos), 1)), np.tile(orn[:1], (len(orn), 1)))
    elif mistake == "unannounced":
        drawn = draw(pos, orn)
        changed = np.ones(len(pos), dtype=bool)
        announced = np.arange(len(pos)) % 2 == 0
    else:  # outside the catalogue: noise of 1 mm
        drawn = draw(pos, orn) + np.random.default_rng(1).normal(scale=1e-3, size=(len(pos), 8, 3))
    verdicts = judge(recording([box_frame()], [(pos, orn)], [track(drawn, changed=changed, announced=announced)]))
    assert check in _failing(verdicts)
    found = [d for v in verdicts.values() for d in v.diagnoses]
    if diagnosis is None:
        assert found == [], "a mistake outside the catalogue must get no diagnosis"
    else:
        assert found and set(found) == {diagnosis}, verdicts[check].message()
    assert "box_actor" in verdicts[check].message()


def test_a_base_drawn_at_its_centre_of_mass_is_placed_wrong():
    inertial = np.array([0.05, 0.0, 0.0])
    link_pos, orn = motion()
    # the app draws the shape around getBasePositionAndOrientation: the link frame moved by the inertial offset
    com = link_pos + Rotation.from_quat(orn).apply(inertial)
    verdicts = judge(recording([box_frame(inertial=inertial)], [(link_pos, orn)], [track(draw(com, orn))]))
    assert _failing(verdicts) == {"placed"}
    assert verdicts["placed"].diagnoses == ["com-frame"]


def test_vertex_ranges_swapped_between_bodies_are_placed_wrong():
    a, b = motion(seed=1), motion(seed=2, offset=(1.0, 0.0, 0.0))
    # one actor, two ranges: the first drawn by body b's pose at body a's place, and the reverse
    shift = a[0][0] - b[0][0]
    first = draw(*b, CORNERS + Rotation.from_quat(b[1][0]).inv().apply(shift))
    second = draw(*a, CORNERS - Rotation.from_quat(a[1][0]).inv().apply(shift))
    verdicts = judge(recording([box_frame(0), box_frame(1)], [a, b], [track(np.concatenate([first, second], axis=1))]))
    assert "placed" in _failing(verdicts)
    assert "other-body" in verdicts["placed"].diagnoses


def test_normals_that_do_not_turn_fail_the_normals_check():
    pos, orn = motion()
    normals = CORNERS / np.linalg.norm(CORNERS, axis=1, keepdims=True)
    right = np.einsum("tij,nj->tni", Rotation.from_quat(orn).as_matrix(), normals)
    stale = np.broadcast_to(right[:1], right.shape)
    assert _failing(judge(recording([box_frame()], [(pos, orn)], [track(draw(pos, orn), normals=right)]))) == set()
    verdicts = judge(recording([box_frame()], [(pos, orn)], [track(draw(pos, orn), normals=stale)]))
    assert _failing(verdicts) == {"normals"} and verdicts["normals"].diagnoses == ["stale-normals"]


def test_a_static_decoration_and_a_static_body_are_not_required_to_move():
    pos, orn = motion()
    still = (np.tile([[0.0, 0.0, -0.1]], (len(pos), 1)), np.tile([[0, 0, 0, 1.0]], (len(pos), 1)))
    floor = draw(*still)  # drawn where the static body is, never moved
    verdicts = judge(recording([box_frame(0), box_frame(1)], [(pos, orn), still], [track(draw(pos, orn)), track(floor, label="floor")]))
    assert _failing(verdicts) == set()


def test_an_app_that_raised_fails_runs():
    pos, orn = motion()
    rec = recording([box_frame()], [(pos, orn)], [track(draw(pos, orn))])
    rec.error = "the app raised at tick 3: ValueError: boom"
    assert _failing(judge(rec)) == {"runs"}
