"""Recordings made by hand, for testing the app judgement without FURY or pyBullet: one box body that
moves and turns (or a few), drawn by one actor in whatever way a test asks."""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from conformance.apps.bodies import Frame
from conformance.apps.recording import ActorTrack, Recording

HALF = np.array([0.1, 0.2, 0.05])
#: the 8 corners of the box, in its link frame
CORNERS = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float) * HALF
TICKS = 40


def box_frame(body: int = 0, inertial=(0.0, 0.0, 0.0)) -> Frame:
    # getCollisionShapeData's box dims are full extents; the shape sits at the link frame's origin
    return Frame(0, body, -1, f"box{body}", 1.0, (("box", tuple(2 * HALF), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)),),
                 tuple(inertial))


def motion(ticks: int = TICKS, seed: int = 0, offset=(0.0, 0.0, 0.0)):
    """Link-frame poses ``(T+1, 3)``, ``(T+1, 4)`` of a body falling, drifting and tumbling about all axes."""
    rng = np.random.default_rng(seed)
    t = np.arange(ticks + 1) / 240.0
    velocity, spin = rng.normal(size=3), rng.normal(size=3) * 3
    positions = np.array(offset) + np.array([0.0, 0.0, 2.0]) + t[:, None] * velocity - 0.5 * 9.8 * t[:, None] ** 2 * [0, 0, 1]
    start = Rotation.from_rotvec(rng.normal(size=3))
    orientations = (Rotation.from_rotvec(t[:, None] * spin) * start).as_quat()
    return positions, orientations


def draw(positions, orientations, geometry=CORNERS) -> np.ndarray:
    """World vertices ``(T+1, n, 3)`` of ``geometry`` at the given poses."""
    rotations = Rotation.from_quat(orientations).as_matrix()
    return np.einsum("tij,nj->tni", rotations, geometry) + positions[:, None, :]


def recording(frames, poses, tracks, *, before=None, events=()) -> Recording:
    """A recording of ``frames`` with ``poses`` (list of (positions, orientations), one per frame) and
    actor ``tracks``; ``before`` are the poses just before each tick's step (default: the previous tick's)."""
    positions = np.stack([p for p, _ in poses], axis=1)
    orientations = np.stack([q for _, q in poses], axis=1)
    if before is None:
        before_positions = np.concatenate([positions[:1], positions[:-1]])
        before_orientations = np.concatenate([orientations[:1], orientations[:-1]])
    else:
        before_positions, before_orientations = before
    steps = np.ones(len(positions), dtype=int)
    steps[0] = 0
    return Recording("hand-made.py", "none", list(tracks), list(frames), positions, orientations, before_positions,
                     before_orientations, steps, "by hand", "", list(events))


def track(vertices, *, normals=None, label="box_actor", changed=None, announced=None) -> ActorTrack:
    ticks = len(vertices)
    changed = np.ones(ticks, dtype=bool) if changed is None else changed
    announced = changed.copy() if announced is None else announced
    return ActorTrack(label, "Mesh", vertices, normals, changed, announced)
