"""Pose arithmetic (positions + x, y, z, w quaternions) on top of ``scipy.spatial.transform``."""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

__all__ = ["apply", "compose", "euler_matrices", "invert", "matrices"]


def matrices(orientations) -> np.ndarray:
    """Rotation matrices ``(..., 3, 3)`` of x, y, z, w quaternions (any norm)."""
    q = np.asarray(orientations, dtype=np.float64)
    return Rotation.from_quat(q.reshape(-1, 4)).as_matrix().reshape(q.shape[:-1] + (3, 3))


def apply(position, orientation, points) -> np.ndarray:
    """``points`` (n, 3) expressed in the frame (position, orientation), in world coordinates."""
    return np.asarray(points, dtype=np.float64) @ matrices(orientation).T + np.asarray(position, dtype=np.float64)


def compose(pos_a, orn_a, pos_b, orn_b):
    """Frame b given in frame a, expressed in the world: a ∘ b."""
    ra = Rotation.from_quat(orn_a)
    return ra.apply(pos_b) + np.asarray(pos_a, dtype=np.float64), (ra * Rotation.from_quat(orn_b)).as_quat()


def invert(position, orientation):
    r = Rotation.from_quat(orientation).inv()
    return -r.apply(position), r.as_quat()


def euler_matrices(orientations, order: str, which=(0, 1, 2)) -> np.ndarray:
    """What pyBullet's Euler angles of ``orientations`` (roll, pitch, yaw: ``getEulerFromQuaternion``,
    about fixed x, y, z) draw when composed in scipy's intrinsic ``order`` with the angles taken in the
    order ``which`` (indices into roll, pitch, yaw): the rotation matrices ``(..., 3, 3)`` a renderer
    makes of them. VTK's ``SetOrientation(roll, pitch, yaw)`` is ``("ZXY", (2, 0, 1))``."""
    import warnings

    q = np.asarray(orientations, dtype=np.float64)
    with warnings.catch_warnings():  # at pitch ±90° scipy zeroes one angle, as getEulerFromQuaternion does
        warnings.simplefilter("ignore", UserWarning)
        angles = Rotation.from_quat(q.reshape(-1, 4)).as_euler("xyz")
    return Rotation.from_euler(order, angles[:, list(which)]).as_matrix().reshape(q.shape[:-1] + (3, 3))
