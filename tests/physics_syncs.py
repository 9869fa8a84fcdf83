"""Sync implementations that hide what physics does, for the render part of the filter checks."""

from __future__ import annotations

import numpy as np

from conformance.implementations.reference import ReferenceSync


class KeepsApart(ReferenceSync):
    """Wrong: draws the crossing pair as if they had bounced off each other: body ``b`` is never
    drawn closer than 1.2 m beyond ``a`` along x, whatever physics says."""

    def _poses(self):
        positions, matrices = super()._poses()
        names = [t.name for t in self.targets]
        a, b = names.index("a"), names.index("b")
        positions[b] = np.maximum(positions[b], positions[a] + (1.2, -np.inf, -np.inf))
        return positions, matrices
