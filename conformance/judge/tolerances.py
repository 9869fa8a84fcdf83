"""How far a drawn vertex may be from where pybullet puts it: the one place tolerances are set.

A correct sync makes two kinds of error, and the tolerance allows for both, no more:

* float32 vertex storage: FURY 0.12 keeps its sphere vertices, FURY 2 every vertex (and any array a
  sync writes back) in float32, whose rounding is at most 2⁻²⁴ of the coordinate; we allow 4× that of the largest world
  coordinate of the body (``POSITION_RTOL`` × distance from the origin + size);
* pybullet's float32 quaternion helpers (``getMatrixFromQuaternion``, ``getDifferenceQuaternion``,
  ``multiplyTransforms``…) are off by up to ~4e-6 (pybullet-facts.md, "Quaternions"), which moves a
  vertex by up to 4e-6 × its distance from the body's frame; we allow 2.5× that (``SIZE_RTOL``).

So ``tolerance = SIZE_RTOL · extent + POSITION_RTOL · (|origin distance| + extent) + ATOL``.
A sync that is one step late at 1 m/s is off by 4 mm: a thousand times more.

Vertex normals (stored for spheres) must point within ``normal_angle`` radians of the body's
rotated normals: float32 storage and pybullet's float32 helpers account for ~1e-6; we allow 1e-4.

World bounds agree with ``getAABB`` when the drawn box lies inside pybullet's (within the vertex
tolerance) and reaches it on every side within ``bounds_rtol`` (2.5 %) of the shape's size, beyond
the amount by which pybullet's box is itself larger than the shape: FURY's spheres are tessellated
with 16 segments, so in the worst direction their vertices reach cos(π/16) = 98.1 % of the radius.
pybullet's box is exact for boxes, and for spheres at their centre of mass; for cylinders, and for
shapes off the centre of mass (a compound), it is a box around a turned box, up to 1.3× the
shape's size larger (measured over random turns); the kit predicts that looseness from pybullet's
pose (:func:`conformance.bullet.truth.aabb_half_extents`) rather than allowing it everywhere.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Tolerance", "DEFAULT"]


@dataclass(frozen=True)
class Tolerance:
    size_rtol: float = 1e-5
    position_rtol: float = 2.4e-7
    atol: float = 1e-9
    normal_angle: float = 1e-4
    bounds_rtol: float = 0.025

    def for_geometry(self, local: np.ndarray, position) -> float:
        """Tolerance for a body whose link-frame geometry is ``local`` and whose frame is at ``position``."""
        extent = float(np.max(np.linalg.norm(local, axis=1))) if len(local) else 0.0
        distance = float(np.linalg.norm(position))
        return self.size_rtol * extent + self.position_rtol * (distance + extent) + self.atol

    def for_extents(self, extents: np.ndarray, positions: np.ndarray) -> np.ndarray:
        """:meth:`for_geometry` of many bodies at once, given each one's extent (largest vertex
        distance from its link frame) and frame position ``(n, 3)``."""
        distances = np.linalg.norm(np.asarray(positions, dtype=np.float64), axis=1)
        return self.size_rtol * extents + self.position_rtol * (distances + extents) + self.atol

    def describe(self) -> str:
        return f"{self.size_rtol:g}·size + {self.position_rtol:g}·(distance from origin + size) + {self.atol:g} m"


DEFAULT = Tolerance()
