"""Deliberately wrong sync implementations: realistic mistakes that ``pytest conformance/ --sync <it>`` must fail.

Most of them are ``Baseline`` (``right_syncs.PerTargetSync``, a plain, correct per-target sync) with
one method rewritten the way a user gets it wrong, so that the mistake is the only difference and
the kit's verdict is about that mistake alone (``PerTargetSync`` itself must pass, and
``tests/test_discrimination.py`` checks that it does). ``DoesNothing`` is written from scratch.

Every class's docstring starts with "Wrong:" and says what the mistake is and where people make it.
The same classes under the same names on both backends, so ``--sync wrong_syncs:<Name>`` means the
same mistake in either environment, and the kill-rate tables line up by name. Where each lives:

* here, written once: the mistakes that never touch the renderer, in a pose, a rotation matrix,
  which targets are synced, when, or in pybullet (``Baseline`` is the backend's ``PerTargetSync``,
  from the ``right_syncs`` dispatcher);
* ``wrong_syncs_vtk`` (FURY 0.12) and ``wrong_syncs_pygfx`` (FURY 2), re-exported here: the mistakes
  made through the renderer's own API (actor rotations and scales, vertex ranges, normals, colours,
  announcing changes), each made the way a user of that FURY makes it; their renderer-free halves
  are mixins in ``sync_steps``.
"""

from __future__ import annotations

import importlib

import numpy as np

from conformance import backends
from right_syncs import PerTargetSync as Baseline  # the correct sync each mistake departs from

__all__ = [
    "CentreNotUpdated",
    "ConjugateQuaternion",
    "DoesNothing",
    "EulerRotateXYZ",
    "FirstMultibodyOnly",
    "Float32Incremental",
    "ForgetsModified",
    "IgnoresBaseInertialFrame",
    "InflatedAgainstZFighting",
    "LinkCOMFrame",
    "NormalsNotRotated",
    "OneStepLate",
    "QuaternionWXYZ",
    "SkipsLastTarget",
    "StaleLinkState",
    "StaticPlacedOnce",
    "TintsMovingBodies",
    "TransposedRotation",
    "VelocityGated",
    "WritesPoseBack",
    "WrongVertexRange",
]

# ---- made through the renderer: one module per FURY -------------------------------------------------

_renderer = importlib.import_module(f"wrong_syncs_{backends.NAME}")
CentreNotUpdated = _renderer.CentreNotUpdated
EulerRotateXYZ = _renderer.EulerRotateXYZ
Float32Incremental = _renderer.Float32Incremental
ForgetsModified = _renderer.ForgetsModified
InflatedAgainstZFighting = _renderer.InflatedAgainstZFighting
NormalsNotRotated = _renderer.NormalsNotRotated
TintsMovingBodies = _renderer.TintsMovingBodies
WrongVertexRange = _renderer.WrongVertexRange


# ---- rotations ---------------------------------------------------------------------------------------

class TransposedRotation(Baseline):
    """Wrong: reads getMatrixFromQuaternion's nine numbers column-major ("GPU matrices are
    column-major"), so every body is drawn with the transpose — the inverse — of its rotation.

    Diagnosis: conjugate
    """

    def matrix(self, orn):
        return np.reshape(self.p.getMatrixFromQuaternion(orn), (3, 3), order="F")


class QuaternionWXYZ(Baseline):
    """Wrong: unpacks pybullet's (x, y, z, w) quaternion as (w, x, y, z), the order of transforms3d,
    Eigen's constructor and most textbooks, then uses the textbook matrix formula (pygfx's
    ``local.rotation`` takes x, y, z, w like pybullet; the mistake is in the hand-written helper).

    Diagnosis: scalar-first
    """

    def matrix(self, orn):
        w, x, y, z = orn
        return np.array([
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ])


class ConjugateQuaternion(Baseline):
    """Wrong: takes pybullet's orientation for a world-to-body rotation and inverts it first
    (``p.invertTransform``'s quaternion, i.e. the conjugate), so bodies turn the wrong way.

    Diagnosis: conjugate
    """

    def matrix(self, orn):
        _, inverse = self.p.invertTransform([0, 0, 0], orn)
        return np.reshape(self.p.getMatrixFromQuaternion(inverse), (3, 3))


# ---- frames --------------------------------------------------------------------------------------------

class LinkCOMFrame(Baseline):
    """Wrong: draws links at getLinkState()[0:2], the link's centre-of-mass frame, instead of [4:6],
    its URDF link frame (the first two entries look like "the link's position and orientation").

    Diagnosis: com-frame
    """

    def link_pose(self, t):
        if t.link >= 0:
            return self.p.getLinkState(t.body, t.link, computeForwardKinematics=1)[0:2]
        return super().link_pose(t)


class StaleLinkState(Baseline):
    """Wrong: getLinkState(body, link)[4:6] without computeForwardKinematics=1 (as the guide's
    sync_joints does): on pybullet 3.2.7 the cached link poses are those of the previous step.

    Diagnosis: previous-step
    """

    def link_pose(self, t):
        if t.link >= 0:
            return self.p.getLinkState(t.body, t.link)[4:6]
        return super().link_pose(t)


class FirstMultibodyOnly(Baseline):
    """Wrong: reads every link's pose from the first body that has links (the guide's sync_joints
    takes one global ``multibody``; adapted to a scene with several robots, link ``i`` of each is
    drawn where link ``i`` of the first one is).

    Diagnosis: other-target
    """

    def __init__(self, world):
        super().__init__(world)
        self.multibody = next((t.body for t in self.targets if t.link >= 0), None)

    def link_pose(self, t):
        if t.link >= 0:
            return self.p.getLinkState(self.multibody, t.link, computeForwardKinematics=1)[4:6]
        return super().link_pose(t)


class IgnoresBaseInertialFrame(Baseline):
    """Wrong: draws a base at getBasePositionAndOrientation, which is its centre-of-mass frame, not its
    link frame (as the guide does): wrong for any base created with baseInertialFramePosition or
    Orientation, or loaded from a URDF whose base <inertial> has an <origin>.

    Diagnosis: com-frame
    """

    def link_pose(self, t):
        if t.link == -1:
            return self.p.getBasePositionAndOrientation(t.body)
        return super().link_pose(t)


# ---- timing --------------------------------------------------------------------------------------------

class OneStepLate(Baseline):
    """Wrong: double-buffers poses ("read now, draw next frame, to overlap physics and rendering"),
    so every frame shows the pose of the step before — what the guide's timer callback draws when it
    syncs before stepSimulation instead of after.

    Diagnosis: previous-step
    """

    def __init__(self, world):
        super().__init__(world)
        self.previous = None

    def __call__(self):
        current = {t.name: self.link_pose(t) for t in self.targets}
        shown = self.previous or current
        self.draw((t, *shown[t.name]) for t in self.targets)
        self.previous = current


# ---- which bodies --------------------------------------------------------------------------------------

class SkipsLastTarget(Baseline):
    """Wrong: an off-by-one in the loop over bodies (``range(len(targets) - 1)``, written when the last
    body was the ground plane), so the last body is never moved.

    Diagnosis: never-moved
    """

    def to_sync(self):
        return [self.targets[i] for i in range(len(self.targets) - 1)]


class StaticPlacedOnce(Baseline):
    """Wrong: places bodies of mass 0 (the ground, walls, a robot's fixed base) on the first frame and
    never again ("static bodies do not move"): a static body moved by resetBasePositionAndOrientation
    stays drawn where it was.

    Diagnosis: before-event
    """

    def __init__(self, world):
        super().__init__(world)
        self.static = {t.name for t in self.targets if self.p.getDynamicsInfo(t.body, t.link)[0] == 0}
        self.placed = False

    def to_sync(self):
        if not self.placed:
            self.placed = True
            return self.targets
        return [t for t in self.targets if t.name not in self.static]


class VelocityGated(Baseline):
    """Wrong: after the first frame, skips bodies whose velocity is exactly zero ("a body at rest has not
    moved"): but resetBasePositionAndOrientation moves a body and leaves its velocity zero (pybullet
    3.2.7 zeroes it, and a static body's is always zero), so a teleported body stays drawn where it was.

    Diagnosis: before-event
    """

    def __init__(self, world):
        super().__init__(world)
        self.first = True

    def moving(self, t) -> bool:
        if t.link == -1:
            linear, angular = self.p.getBaseVelocity(t.body)
        else:
            linear, angular = self.p.getLinkState(t.body, t.link, computeLinkVelocity=1,
                                                  computeForwardKinematics=1)[6:8]
        return any(linear) or any(angular)

    def to_sync(self):
        if self.first:
            self.first = False
            return self.targets
        return [t for t in self.targets if self.moving(t)]


# ---- side effects ----------------------------------------------------------------------------------

class WritesPoseBack(Baseline):
    """Wrong: writes the float32-rounded pose it drew back into pybullet with
    resetBasePositionAndOrientation ("so physics and graphics agree exactly"): the sync changes the
    simulation it is supposed to only watch.

    Diagnosis: -
    """

    def __call__(self):
        super().__call__()
        for t in self.targets:
            if t.link == -1 and self.p.getDynamicsInfo(t.body, -1)[0] > 0:
                pos, orn = self.p.getBasePositionAndOrientation(t.body)
                self.p.resetBasePositionAndOrientation(
                    t.body, np.float32(pos).tolist(), (np.float32(orn) / np.linalg.norm(np.float32(orn))).tolist())


class DoesNothing:
    """Wrong: never moves anything (a sync function that was written and never wired up).

    Diagnosis: never-moved
    """

    def __init__(self, world):
        pass

    def __call__(self):
        pass
