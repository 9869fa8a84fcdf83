"""App mode on what right robot and FURY 2 programs draw: welded frames (a URDF's fixed joints) and
impostor spheres (FURY 2's default ``actor.sphere``), on recordings made by hand (issue 28, point 4).
The whole programs are ``examples/*/r2d2.py`` and ``examples/pygfx/ball_pit.py``, with a mistake each
in ``wrong/`` (``tests/test_examples.py``)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import app_recordings as rec
from conformance.apps import judge, welds
from conformance.apps.bodies import Frame

IDENTITY = (0.0, 0.0, 0.0, 1.0)


PLATE = np.array([[x, y, z] for x in (-0.2, 0.2) for y in (-0.2, 0.2) for z in (-0.01, 0.01)])


def _welded_pair(ticks: int = rec.TICKS):
    """A body (a box) and a link welded to it 0.3 m along its x axis, moving and turning together: a thin
    plate whose collision shape is a mesh (as a URDF's finger tip is), held as pyBullet gives it."""
    positions, orientations = rec.motion(ticks)
    turns = Rotation.from_quat(orientations)
    plate = (positions + turns.apply([0.3, 0.0, 0.0]), orientations)
    mesh = Frame(0, 0, 0, "plate", 1.0, (("mesh", (1.0, 1.0, 1.0), (0.0, 0.0, 0.0), IDENTITY),),
                 mesh=tuple(map(tuple, PLATE)))
    return [rec.box_frame(0), mesh], [(positions, orientations), plate]


def test_frames_whose_relative_pose_stays_constant_are_one_group():
    frames, poses = _welded_pair()
    positions = np.stack([p for p, _ in poses], 1)
    rotations = Rotation.from_quat(np.stack([q for _, q in poses], 1).reshape(-1, 4)).as_matrix().reshape(positions.shape[:2] + (3, 3))
    assert welds.groups(frames, positions, rotations).tolist() == [1, 1]
    # the plate swinging on a hinge instead: not welded
    swing = Rotation.from_rotvec(np.linspace(0, 1, len(positions))[:, None] * [0, 0, 1.0])
    moved = rotations.copy()
    moved[:, 1] = (Rotation.from_matrix(rotations[:, 1]) * swing).as_matrix()
    assert welds.groups(frames, positions, moved).tolist() == [-1, -1]
    # two bodies falling side by side are not welded (the kit's perturbed runs move them apart)
    other = [frames[0], Frame(0, 1, -1, "box1", 1.0, frames[1].shapes)]
    assert welds.groups(other, positions, rotations).tolist() == [-1, -1]


def test_a_welded_link_drawn_by_its_own_actor_is_drawn_and_held_by_itself():
    """Before welded frames were one rigid frame (and a mesh shape had its extent), the plate's vertices
    went to the box, which holds them as well, and ``drawn`` failed the plate: 'moves … but no drawn
    vertex follows it', as it failed R2-D2's finger tips."""
    frames, poses = _welded_pair()
    plate = PLATE
    tracks = [rec.track(rec.draw(*poses[0], rec.CORNERS), label="box_actor"),
              rec.track(rec.draw(*poses[1], plate), label="plate_actor")]
    verdicts = judge(rec.recording(frames, poses, tracks), checks=("attached", "drawn", "placed"))
    assert all(v.passed for v in verdicts.values()), {k: v.lines for k, v in verdicts.items()}
    assert not any("held equally" in note for v in verdicts.values() for note in v.notes)
    # the plate left where it was built is still missed
    still = np.broadcast_to(rec.draw(*poses[1], plate)[:1], (len(poses[1][0]),) + plate.shape)
    tracks[1] = rec.track(np.array(still), label="plate_actor")
    drawn = judge(rec.recording(frames, poses, tracks), checks=("attached", "drawn"))["drawn"]
    assert not drawn.passed and "plate" in " ".join(drawn.lines), drawn.lines


def _impostors(radius: float, drawn_radius: float):
    """A ball of ``radius`` drawn as an impostor sphere: six vertices at its centre, ``drawn_radius``."""
    positions, orientations = rec.motion()
    frame = Frame(0, 0, -1, "ball", 1.0, (("sphere", (radius,), (0.0, 0.0, 0.0), IDENTITY),))
    centre = np.repeat(positions[:, None, :], 6, axis=1)
    track = rec.track(centre, label="ball_actor")
    track.radii = np.full(6, drawn_radius)
    return rec.recording([frame], [(positions, orientations)], [track])


def test_an_impostor_sphere_is_placed_as_the_sphere_it_draws():
    """Six vertices at the centre span nothing: judged as points they were 'not the collision shape';
    with their radius they are the ball, and one twice its size, the ball's only drawing, is the ball drawn
    at the wrong size."""
    right = judge(_impostors(0.2, 0.2), checks=("attached", "placed", "normals"))
    assert all(v.passed for v in right.values()) and not right["placed"].notes, right["placed"].notes
    twice = judge(_impostors(0.2, 0.4), checks=("attached", "placed"))["placed"]
    assert not twice.passed and twice.diagnoses == ["scaled"], twice.message()
    assert "drawn at 2 times the size of its collision shape (sphere) (half extents (0.4, 0.4, 0.4)" in twice.message()


def test_a_note_names_the_ranges_a_frame_holds_not_one_range_over_them():
    """A frame holding vertices 0-2 and 40-63 of an actor is told as ``0:3, 40:64``: ``0:64`` claimed the
    vertices between, held by another frame (notes named overlapping ranges of one actor)."""
    from conformance.apps.recording import vertex_ranges as _ranges

    assert _ranges(np.array([0, 1, 2, 40, 41, 42])) == "0:3, 40:43"
    assert _ranges(np.arange(24)) == "0:24"
    assert _ranges(np.array([0, 2, 4, 6, 8])) == "0:1, 2:3, 4:5 and 2 more ranges"


@pytest.mark.full("whole app runs in processes of their own; CI judges app mode end to end on every example app (test_examples)")
def test_every_note_is_shown_on_asking(tmp_path):
    """``app --notes all`` prints every note of every check; by default a check's notes past three are
    counted, and the count says how to see them (before, '… 26 more notes' and nothing showed them)."""
    import subprocess
    import sys
    from pathlib import Path

    from conformance import backends

    app = Path(__file__).resolve().parent.parent / "examples" / backends.NAME / "r2d2.py"

    def run(*extra):
        done = subprocess.run([sys.executable, "-m", "conformance", "app", str(app), "--ticks", "10", "--perturbed", "0",
                               "--results", str(tmp_path), *extra], capture_output=True, text=True, timeout=600)
        assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
        return done.stdout

    short, everything = run("--notes", "1"), run("--notes", "all")
    assert "more notes (--notes all shows them)" in short and "more notes" not in everything
    assert everything.count("note: ") > short.count("note: ")
