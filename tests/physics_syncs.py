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


class LeavesAForce(ReferenceSync):
    """Wrong: draws right, then pushes every dynamic body up with ``applyExternalForce`` ("to make up for the
    frame the picture lags"): nothing pyBullet reports changes until the next step, which the force moves."""

    def __call__(self):
        super().__call__()
        for t in self.targets:
            if t.link == -1 and self.p.getDynamicsInfo(t.body, -1)[0] > 0:
                pos, _ = self.p.getBasePositionAndOrientation(t.body)
                self.p.applyExternalForce(t.body, -1, [0.0, 0.0, 0.5], pos, 1)  # 1: pybullet.WORLD_FRAME
