"""Sync implementations written for the kit's own tests: realistic mistakes the vertex check must
reject, and correct implementations in other styles that it must accept."""

from __future__ import annotations

import numpy as np
from fury import utils
from scipy.spatial.transform import Rotation
from vtkmodules.vtkCommonMath import vtkMatrix4x4

from conformance.implementations.reference import ReferenceSync


def _pose(p, t):
    """Link-frame pose of a target (the kit's scenes have no base inertial offset)."""
    if t.link == -1:
        return p.getBasePositionAndOrientation(t.body)
    return p.getLinkState(t.body, t.link, computeForwardKinematics=1)[4:6]


class UserMatrixSync:
    """Correct, per-actor style: one 4x4 user matrix per whole actor, vertex rewrite for shared ones."""

    def __init__(self, world):
        self.world = world
        self.local = {}
        for t in world.targets:
            if t.shared:
                points = np.array(utils.vertices_from_actor(t.actor)[t.start:t.stop], dtype=np.float64)
                self.local[t.name] = Rotation.from_quat(t.orientation).inv().apply(points - t.position)

    def __call__(self):
        p = self.world.p
        for t in self.world.targets:
            pos, orn = _pose(p, t)
            rot = Rotation.from_quat(orn)
            if t.shared:
                utils.vertices_from_actor(t.actor)[t.start:t.stop] = rot.apply(self.local[t.name]) + pos
                utils.update_actor(t.actor)
            else:
                m = np.eye(4)
                m[:3, :3], m[:3, 3] = rot.as_matrix(), pos
                vm = vtkMatrix4x4()
                vm.DeepCopy(m.ravel())
                t.actor.SetUserMatrix(vm)


class DoesNothing:
    """Wrong: never moves anything."""

    def __init__(self, world):
        pass

    def __call__(self):
        pass


class OneStepLate(ReferenceSync):
    """Wrong: draws the pose of the previous frame (sync before stepSimulation, as the guide's timer does)."""

    def __init__(self, world):
        super().__init__(world)
        self._pending = None

    def __call__(self):
        p = self.p
        current = [(p.getBasePositionAndOrientation(t.body) if t.link == -1 else None) for t in self.targets]
        if self._pending is not None:
            saved = self.p
            self.p = _Frozen(saved, self._pending, self.targets)
            try:
                super().__call__()
            finally:
                self.p = saved
        else:
            super().__call__()
        self._pending = current


class _Frozen:
    """A pybullet stand-in that reports remembered base poses."""

    def __init__(self, p, poses, targets):
        self._p, self._poses = p, {t.body: pose for t, pose in zip(targets, poses) if pose is not None}

    def getBasePositionAndOrientation(self, body):
        return self._poses[body]

    def __getattr__(self, name):
        return getattr(self._p, name)


class TransposedRotation(ReferenceSync):
    """Wrong: uses the rotation's transpose (row- vs column-vector confusion)."""

    def _poses(self):
        positions, matrices = super()._poses()
        return positions, np.transpose(matrices, (0, 2, 1))
