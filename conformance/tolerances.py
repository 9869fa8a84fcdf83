"""How far a drawn vertex may be from where pybullet puts it: the one place tolerances are set.

A correct sync makes two kinds of error, and the tolerance allows for both, no more:

* float32 vertex storage: VTK keeps FURY's sphere vertices (and any array a sync writes back) in
  float32, whose rounding is at most 2⁻²⁴ of the coordinate; we allow 4× that of the largest world
  coordinate of the body (``POSITION_RTOL`` × distance from the origin + size);
* pybullet's float32 quaternion helpers (``getMatrixFromQuaternion``, ``getDifferenceQuaternion``,
  ``multiplyTransforms``…) are off by up to ~4e-6 (pybullet-facts.md, "Quaternions"), which moves a
  vertex by up to 4e-6 × its distance from the body's frame; we allow 2.5× that (``SIZE_RTOL``).

So ``tolerance = SIZE_RTOL · extent + POSITION_RTOL · (|origin distance| + extent) + ATOL``.
A sync that is one step late at 1 m/s is off by 4 mm: a thousand times more.
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

    def for_geometry(self, local: np.ndarray, position) -> float:
        """Tolerance for a body whose link-frame geometry is ``local`` and whose frame is at ``position``."""
        extent = float(np.max(np.linalg.norm(local, axis=1))) if len(local) else 0.0
        distance = float(np.linalg.norm(position))
        return self.size_rtol * extent + self.position_rtol * (distance + extent) + self.atol

    def describe(self) -> str:
        return f"{self.size_rtol:g}·size + {self.position_rtol:g}·(distance from origin + size) + {self.atol:g} m"


DEFAULT = Tolerance()
