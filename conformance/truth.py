"""Where pybullet says each drawn thing is, computed by the kit alone.

The expected world vertices of a target are its reference geometry (captured in the link frame
when the actor was built) moved by pybullet's pose of that link frame:

* a base: ``getBasePositionAndOrientation`` gives the centre-of-mass frame (pybullet-facts.md,
  "Frames"); the base link frame is that frame composed with the inverse of the local inertial
  frame from ``getDynamicsInfo(body, -1)[3:5]``;
* a link: ``getLinkState(body, link, computeForwardKinematics=1)[4:6]``, the URDF link frame, with
  forward kinematics recomputed so the pose is not one step stale.

Nothing here reads a sync implementation's state or an actor.
"""

from __future__ import annotations

from typing import Sequence

import numpy as np

from scipy.spatial.transform import Rotation

from conformance import poses
from conformance.client import BoundClient

__all__ = ["link_frame", "link_frames", "expected_vertices"]


def link_frame(p: BoundClient, body: int, link: int) -> tuple[np.ndarray, np.ndarray]:
    """World pose (position, x-y-z-w quaternion) of the link frame of ``body``/``link``."""
    if link == -1:
        com_pos, com_orn = p.getBasePositionAndOrientation(body)
        local_pos, local_orn = p.getDynamicsInfo(body, -1)[3:5]
        inv_pos, inv_orn = poses.invert(local_pos, local_orn)
        return poses.compose(com_pos, com_orn, inv_pos, inv_orn)
    state = p.getLinkState(body, link, computeForwardKinematics=1)
    return np.asarray(state[4], dtype=np.float64), np.asarray(state[5], dtype=np.float64)


def link_frames(p: BoundClient, items: Sequence[tuple[int, int]]) -> tuple[np.ndarray, np.ndarray]:
    """Link-frame poses of many (body, link) pairs: positions ``(n, 3)`` and quaternions ``(n, 4)``.

    The same arithmetic as :func:`link_frame`, batched: one scipy call for all bases."""
    n = len(items)
    positions = np.empty((n, 3))
    orientations = np.empty((n, 4))
    bases = [i for i, (_, link) in enumerate(items) if link == -1]
    for i, (body, link) in enumerate(items):
        if link >= 0:
            state = p.getLinkState(body, link, computeForwardKinematics=1)
            positions[i], orientations[i] = state[4], state[5]
    if bases:
        com = [p.getBasePositionAndOrientation(items[i][0]) for i in bases]
        inertial = [p.getDynamicsInfo(items[i][0], -1)[3:5] for i in bases]
        com_rot = Rotation.from_quat([c[1] for c in com])
        frame_rot = com_rot * Rotation.from_quat([l[1] for l in inertial]).inv()
        positions[bases] = np.array([c[0] for c in com]) - frame_rot.apply(np.array([l[0] for l in inertial]))
        orientations[bases] = frame_rot.as_quat()
    return positions, orientations


def expected_vertices(local: np.ndarray, position, orientation) -> np.ndarray:
    """Reference geometry ``local`` (n, 3, link frame) placed at the given link-frame pose."""
    return poses.apply(position, orientation, local)
