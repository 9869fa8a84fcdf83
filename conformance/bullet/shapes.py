"""Distances from points to pybullet's primitive collision shapes, in the shape's own frame."""

from __future__ import annotations

import numpy as np
import pybullet

from conformance.bullet import poses

__all__ = ["compose", "kind_name", "problems", "to_frame"]

#: How much of each axis the drawn vertices must reach: tessellated spheres fall ~0.6 % short.
SPAN_RTOL = 0.01

_KINDS = {pybullet.GEOM_BOX: "box", pybullet.GEOM_SPHERE: "sphere", pybullet.GEOM_CYLINDER: "cylinder"}

compose = poses.compose


def kind_name(geometry: int) -> str:
    return _KINDS.get(geometry, f"geometry type {geometry}")


def to_frame(position, orientation, points) -> np.ndarray:
    """World ``points`` expressed in the frame (position, orientation)."""
    inv_pos, inv_orn = poses.invert(position, orientation)
    return poses.apply(inv_pos, inv_orn, points)


def _distance_to_box(p: np.ndarray, half: np.ndarray) -> np.ndarray:
    q = np.abs(p) - half
    outside = np.linalg.norm(np.maximum(q, 0.0), axis=1)
    inside = np.minimum(np.max(q, axis=1), 0.0)
    return np.abs(outside + inside)


def _distance_to_cylinder(p: np.ndarray, radius: float, height: float) -> np.ndarray:
    q = np.stack([np.hypot(p[:, 0], p[:, 1]) - radius, np.abs(p[:, 2]) - height / 2], axis=1)
    outside = np.linalg.norm(np.maximum(q, 0.0), axis=1)
    inside = np.minimum(np.max(q, axis=1), 0.0)
    return np.abs(outside + inside)


def problems(geometry: int, dimensions, points: np.ndarray, tolerance: float) -> list[str]:
    """What is wrong with ``points`` (in the shape frame) as a drawing of this collision shape."""
    dims = np.asarray(dimensions, dtype=np.float64)
    if geometry == pybullet.GEOM_BOX:
        reach = dims / 2
        distance = _distance_to_box(points, reach)
    elif geometry == pybullet.GEOM_SPHERE:
        reach = np.full(3, dims[0])
        distance = np.abs(np.linalg.norm(points, axis=1) - dims[0])
    elif geometry == pybullet.GEOM_CYLINDER:
        height, radius = dims[0], dims[1]
        reach = np.array([radius, radius, height / 2])
        distance = _distance_to_cylinder(points, radius, height)
    else:
        return [f"collision shape is {kind_name(geometry)}, which the kit cannot draw"]
    found = []
    if not np.isfinite(points).all():
        return ["drawn vertices are not finite"]
    worst = int(np.argmax(distance))
    if distance[worst] > tolerance:
        found.append(f"vertex {worst} at {np.round(points[worst], 6).tolist()} (shape frame) is {distance[worst]:.3g} m "
                     f"off the {kind_name(geometry)}'s surface (tolerance {tolerance:.3g} m)")
    span = np.max(np.abs(points), axis=0)
    short = span < reach * (1 - SPAN_RTOL) - tolerance
    if short.any():
        axes = ", ".join(f"{'xyz'[a]} reaches {span[a]:.4g} of {reach[a]:.4g} m" for a in np.flatnonzero(short))
        found.append(f"drawn vertices do not span the {kind_name(geometry)}: {axes}")
    return found
