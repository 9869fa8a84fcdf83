"""Deliberately wrong sync implementations: realistic mistakes that ``pytest conformance/ --sync <it>`` must fail.

Most of them are ``Baseline`` (``right_syncs.PerTargetSync``, a plain, correct per-target sync) with
one method rewritten the way a user gets it wrong, so that the mistake is the only difference and
the kit's verdict is about that mistake alone (``PerTargetSync`` itself must pass, and
``tests/test_discrimination.py`` checks that it does). The rest are written from scratch in the style
they imitate (the guide's incremental vertex recipe, actor Euler angles, velocity gating).

Every class's docstring starts with "Wrong:" and says what the mistake is and where people make it.
"""

from __future__ import annotations

from collections import defaultdict

import numpy as np
from fury import utils
from scipy.spatial.transform import Rotation
from vtkmodules.util import numpy_support

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
    "WrongVertexRange",
    "WritesPoseBack",
]


# ---- rotations ---------------------------------------------------------------------------------------

class TransposedRotation(Baseline):
    """Wrong: reads getMatrixFromQuaternion's nine numbers column-major ("VTK and OpenGL matrices are
    column-major"), so every body is drawn with the transpose — the inverse — of its rotation."""

    def matrix(self, orn):
        return np.reshape(self.p.getMatrixFromQuaternion(orn), (3, 3), order="F")


class QuaternionWXYZ(Baseline):
    """Wrong: unpacks pybullet's (x, y, z, w) quaternion as (w, x, y, z), the order of transforms3d,
    Eigen's constructor and most textbooks, then uses the textbook matrix formula."""

    def matrix(self, orn):
        w, x, y, z = orn
        return np.array([
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ])


class ConjugateQuaternion(Baseline):
    """Wrong: takes pybullet's orientation for a world-to-body rotation and inverts it first
    (``p.invertTransform``'s quaternion, i.e. the conjugate), so bodies turn the wrong way."""

    def matrix(self, orn):
        _, inverse = self.p.invertTransform([0, 0, 0], orn)
        return np.reshape(self.p.getMatrixFromQuaternion(inverse), (3, 3))


class EulerRotateXYZ:
    """Wrong: resets the actor and applies pybullet's Euler angles with RotateX, RotateY, RotateZ in
    that order. VTK's Rotate* turn about the actor's own (already turned) axes, giving Rx·Ry·Rz,
    while getEulerFromQuaternion's angles mean Rz·Ry·Rx: right only for turns about one axis. (The
    guide's SetOrientation recipe is the same mistake in VTK's Z-X-Y order.)"""

    def __init__(self, world):
        self.p = world.p
        self.whole = [t for t in world.targets if not t.shared]
        self.shared = Baseline(world)  # vertex ranges of shared actors are moved correctly
        self.shared.targets = [t for t in world.targets if t.shared]

    def __call__(self):
        for t in self.whole:
            pos, orn = self.shared.link_pose(t)
            roll, pitch, yaw = np.degrees(self.p.getEulerFromQuaternion(orn))
            t.actor.SetOrientation(0, 0, 0)
            t.actor.RotateX(roll)
            t.actor.RotateY(pitch)
            t.actor.RotateZ(yaw)
            t.actor.SetPosition(*pos)
        self.shared()


# ---- frames --------------------------------------------------------------------------------------------

class LinkCOMFrame(Baseline):
    """Wrong: draws links at getLinkState()[0:2], the link's centre-of-mass frame, instead of [4:6],
    its URDF link frame (the first two entries look like "the link's position and orientation")."""

    def link_pose(self, t):
        if t.link >= 0:
            return self.p.getLinkState(t.body, t.link, computeForwardKinematics=1)[0:2]
        return super().link_pose(t)


class StaleLinkState(Baseline):
    """Wrong: getLinkState(body, link)[4:6] without computeForwardKinematics=1 (as the guide's
    sync_joints does): on pybullet 3.2.7 the cached link poses are those of the previous step."""

    def link_pose(self, t):
        if t.link >= 0:
            return self.p.getLinkState(t.body, t.link)[4:6]
        return super().link_pose(t)


class FirstMultibodyOnly(Baseline):
    """Wrong: reads every link's pose from the first body that has links (the guide's sync_joints
    takes one global ``multibody``; adapted to a scene with several robots, link ``i`` of each is
    drawn where link ``i`` of the first one is)."""

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
    Orientation, or loaded from a URDF whose base <inertial> has an <origin>."""

    def link_pose(self, t):
        if t.link == -1:
            return self.p.getBasePositionAndOrientation(t.body)
        return super().link_pose(t)


# ---- timing --------------------------------------------------------------------------------------------

class OneStepLate(Baseline):
    """Wrong: double-buffers poses ("read now, draw next frame, to overlap physics and rendering"),
    so every frame shows the pose of the step before — what the guide's timer callback draws when it
    syncs before stepSimulation instead of after."""

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
    body was the ground plane), so the last body is never moved."""

    def to_sync(self):
        return [self.targets[i] for i in range(len(self.targets) - 1)]


class StaticPlacedOnce(Baseline):
    """Wrong: places bodies of mass 0 (the ground, walls, a robot's fixed base) on the first frame and
    never again ("static bodies do not move"): a static body moved by resetBasePositionAndOrientation
    stays drawn where it was."""

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
    3.2.7 zeroes it, and a static body's is always zero), so a teleported body stays drawn where it was."""

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


# ---- vertices ------------------------------------------------------------------------------------------

class InflatedAgainstZFighting(Baseline):
    """Wrong: draws every body 0.1 % larger than its collision shape ("so touching bricks do not
    z-fight"): SetScale on whole actors, scaled link-frame geometry in shared ones."""

    SCALE = 1.001

    def __init__(self, world):
        super().__init__(world)
        for name in self.local:
            self.local[name] = self.local[name] * self.SCALE
        for t in self.targets:
            if not t.shared:
                t.actor.SetScale(self.SCALE)


class WrongVertexRange:
    """Wrong: FURY's wrecking-ball example bug: the guide's incremental vertex recipe with the vertices
    per object (``sec``) of every shared actor computed from the object count of the first shared
    actor (the bricks), so the other shared actors (the chain's links) are moved by the wrong ranges."""

    def __init__(self, world):
        self.p = world.p
        self.base = Baseline(world)
        self.whole = [t for t in world.targets if not t.shared]
        by_actor = defaultdict(list)
        for t in world.targets:
            if t.shared:
                by_actor[id(t.actor)].append(t)
        self.groups = []
        num_objects = None
        for members in by_actor.values():
            vertices = utils.vertices_from_actor(members[0].actor)
            if num_objects is None:
                num_objects = len(members)  # the example's brick_centers.shape[0], reused for the chain
            sec = int(vertices.shape[0] / num_objects)
            centers = np.array([t.position for t in members])
            orns = np.array([t.orientation for t in members])
            self.groups.append((members[0].actor, members, sec, centers, orns))

    def __call__(self):
        p = self.p
        for t in self.whole:
            self.base.place_whole(t, *self.base.link_pose(t))
        for actor, members, sec, centers, orns in self.groups:
            vertices = utils.vertices_from_actor(actor)
            for index, t in enumerate(members):
                pos, orn = self.base.link_pose(t)
                rot_mat = np.reshape(p.getMatrixFromQuaternion(p.getDifferenceQuaternion(orn, orns[index])), (3, 3))
                vertices[index * sec: index * sec + sec] = \
                    (vertices[index * sec: index * sec + sec] - centers[index]) @ rot_mat + pos
                centers[index] = pos
                orns[index] = orn
            utils.update_actor(actor)


class CentreNotUpdated:
    """Wrong: the guide's incremental single-actor recipe (turn each vertex range about its tracked
    centre by the rotation since last frame, then move it to the new centre) that updates the tracked
    orientation but forgets ``brick_centers[i] = pos``: every frame turns about a stale centre."""

    def __init__(self, world):
        self.p = world.p
        self.base = Baseline(world)
        self.shared = [t for t in world.targets if t.shared]
        self.whole = [t for t in world.targets if not t.shared]
        self.centers = {t.name: np.array(t.position, dtype=np.float64) for t in self.shared}
        self.orns = {t.name: np.array(t.orientation, dtype=np.float64) for t in self.shared}

    def __call__(self):
        for t in self.whole:
            self.base.place_whole(t, *self.base.link_pose(t))
        actors = {}
        for t in self.shared:
            pos, orn = self.base.link_pose(t)
            vertices = utils.vertices_from_actor(t.actor)
            delta = np.reshape(self.p.getMatrixFromQuaternion(self.p.getDifferenceQuaternion(orn, self.orns[t.name])), (3, 3))
            vertices[t.start:t.stop] = (vertices[t.start:t.stop] - self.centers[t.name]) @ delta + pos
            self.orns[t.name] = orn  # ... and no self.centers[t.name] = pos
            actors[id(t.actor)] = t.actor
        for actor in actors.values():
            utils.update_actor(actor)


class Float32Incremental:
    """Wrong: the incremental recipe applied to every actor's vertices (and normals) in float32 (FURY
    stores sphere vertices as float32; this keeps all its arrays so "to match VTK"): each frame's
    rotation since the last one is rounded to float32 and applied to already rounded vertices, so the
    error random-walks and a body that tumbles for thousands of steps is drawn off its pose."""

    def __init__(self, world):
        self.base = Baseline(world)
        self.targets = list(world.targets)
        self.vertices, self.normals = {}, {}
        for t in self.targets:
            if id(t.actor) not in self.vertices:
                self.vertices[id(t.actor)] = np.array(utils.vertices_from_actor(t.actor), dtype=np.float32)
                normals = t.actor.GetMapper().GetInput().GetPointData().GetNormals()
                if normals is not None:
                    self.normals[id(t.actor)] = numpy_support.vtk_to_numpy(normals)  # float32 already
        self.last = {t.name: (np.array(t.position, np.float32), np.array(t.orientation, np.float32)) for t in self.targets}

    def __call__(self):
        actors = {}
        for t in self.targets:
            pos, orn = self.base.link_pose(t)
            pos, orn = np.asarray(pos, np.float32), np.asarray(orn, np.float32)
            old_pos, old_orn = self.last[t.name]
            delta = (Rotation.from_quat(orn) * Rotation.from_quat(old_orn).inv()).as_matrix().astype(np.float32)
            vertices = self.vertices[id(t.actor)]
            vertices[t.start:t.stop] = (vertices[t.start:t.stop] - old_pos) @ delta.T + pos
            if id(t.actor) in self.normals:
                normals = self.normals[id(t.actor)]
                normals[t.start:t.stop] = normals[t.start:t.stop] @ delta.T
            self.last[t.name] = (pos, orn)
            actors[id(t.actor)] = t.actor
        for key, actor in actors.items():
            utils.vertices_from_actor(actor)[:] = self.vertices[key]
            utils.update_actor(actor)


class NormalsNotRotated(Baseline):
    """Wrong: moves the vertices of shared sphere actors but leaves their stored normals as built, so a
    turned sphere is shaded as if lit from where the light was when it was built (VTK turns normals
    with an actor's matrix, never with rewritten vertices)."""

    def place_shared(self, t, pos, orn):
        utils.vertices_from_actor(t.actor)[t.start:t.stop] = self.local[t.name] @ self.matrix(orn).T + pos

    def finish(self, actors):
        for actor in actors:
            actor.GetMapper().GetInput().GetPoints().Modified()


class ForgetsModified(Baseline):
    """Wrong: writes the new vertices into the numpy view of the points but never calls
    ``utils.update_actor`` / ``Modified()``: VTK does not know the points changed and goes on
    drawing the vertices it uploaded before."""

    def finish(self, actors):
        pass


# ---- side effects ----------------------------------------------------------------------------------

class WritesPoseBack(Baseline):
    """Wrong: writes the float32-rounded pose it drew back into pybullet with
    resetBasePositionAndOrientation ("so physics and graphics agree exactly"): the sync changes the
    simulation it is supposed to only watch."""

    def __call__(self):
        super().__call__()
        for t in self.targets:
            if t.link == -1 and self.p.getDynamicsInfo(t.body, -1)[0] > 0:
                pos, orn = self.p.getBasePositionAndOrientation(t.body)
                self.p.resetBasePositionAndOrientation(
                    t.body, np.float32(pos).tolist(), (np.float32(orn) / np.linalg.norm(np.float32(orn))).tolist())


class TintsMovingBodies(Baseline):
    """Wrong: recolours shared-actor bodies by speed while syncing ("to see what moves"): the vertex
    colours, which a sync must leave alone, change."""

    def place_shared(self, t, pos, orn):
        super().place_shared(t, pos, orn)
        if t.link == -1:
            speed = float(np.linalg.norm(self.p.getBaseVelocity(t.body)[0]))
            colors = utils.colors_from_actor(t.actor)
            colors[t.start:t.stop, :3] = [int(255 * min(speed, 1.0)), 64, 64]


class DoesNothing:
    """Wrong: never moves anything (a sync function that was written and never wired up)."""

    def __init__(self, world):
        pass

    def __call__(self):
        pass
