"""Correct sync implementations, each written in its own style, that the kit must accept.

They are what a careful user might write, not copies of the kit's reference: each computes the
world pose of every target's *link frame* (a base: the centre-of-mass pose from
``getBasePositionAndOrientation`` composed with the inverse of the base's local inertial frame,
``getDynamicsInfo(body, -1)[3:5]``; a link: ``getLinkState(..., computeForwardKinematics=1)[4:6]``),
moves whole actors and the vertex ranges of shared actors there, turns stored vertex normals with
them, and marks what it wrote as modified so that VTK draws it.

* :class:`UserMatrixSync` — one ``vtkMatrix4x4`` per whole actor, a per-target vertex rewrite for
  shared actors; pybullet's own ``multiplyTransforms``/``invertTransform`` for the base offset.
* :func:`vectorised_vertex_sync` — a closure (not a class) that rewrites the vertices of *every*
  actor, whole ones too, with one ``numpy.einsum`` per actor and leaves every actor matrix alone.
* :class:`IncrementalSync` — the guide's incremental idea done in float64: each frame turns what it
  drew last time by the rotation since then (``R_new · R_old⁻¹``, scipy), for whole actors as well
  as vertex ranges, keeping its own float64 copy so that rounding does not pile up in float32.
* :class:`PositionOrientationSync` — ``actor.SetPosition`` + ``actor.SetOrientation`` with the
  Euler angles VTK actually uses: ``SetOrientation(x, y, z)`` builds ``Rz(z)·Rx(x)·Ry(y)``
  (``vtkProp3D::ComputeMatrix`` does RotateZ, RotateX, RotateY, each about the already turned
  axes), so the angles come from ``Rotation.as_euler("ZXY")``; pybullet's matrices for shared
  actors, row by row in a Python loop.
* :class:`PerTargetSync` — the plainest loop: scipy pose per target, user matrix or vertex rewrite,
  ``fury.utils.update_actor``; each method is a step that ``wrong_syncs`` gets wrong in one way.
"""

from __future__ import annotations

import warnings
from collections import defaultdict

import numpy as np
from fury import utils
from scipy.spatial.transform import Rotation
from vtkmodules.util import numpy_support
from vtkmodules.vtkCommonMath import vtkMatrix4x4

__all__ = ["IncrementalSync", "PerTargetSync", "PositionOrientationSync", "UserMatrixSync", "vectorised_vertex_sync"]


def _polydata(actor):
    return actor.GetMapper().GetInput()


def _normals(actor):
    """The actor's stored vertex normals as a writable view, or None (VTK derives them from faces)."""
    array = _polydata(actor).GetPointData().GetNormals()
    return None if array is None else numpy_support.vtk_to_numpy(array)


def _mark_modified(actor) -> None:
    data = _polydata(actor)
    data.GetPoints().Modified()
    if data.GetPointData().GetNormals() is not None:
        data.GetPointData().GetNormals().Modified()


def _user_matrix(rotation: np.ndarray, position) -> vtkMatrix4x4:
    matrix = np.eye(4)
    matrix[:3, :3] = rotation
    matrix[:3, 3] = position
    user = vtkMatrix4x4()
    user.DeepCopy(matrix.ravel())
    return user


def _link_frame_scipy(p, body: int, link: int):
    """Link-frame world pose as (position, scipy Rotation)."""
    if link >= 0:
        state = p.getLinkState(body, link, computeForwardKinematics=1)
        return np.asarray(state[4], dtype=np.float64), Rotation.from_quat(state[5])
    com_pos, com_orn = p.getBasePositionAndOrientation(body)
    inertial_pos, inertial_orn = p.getDynamicsInfo(body, -1)[3:5]
    com = Rotation.from_quat(com_orn)
    to_link = Rotation.from_quat(inertial_orn).inv()
    return com.apply(-to_link.apply(inertial_pos)) + np.asarray(com_pos), com * to_link


class UserMatrixSync:
    """Right: per-actor user matrices; per-target vertex rewrite (and normals) for shared actors."""

    def __init__(self, world):
        self.p = world.p
        self.targets = world.targets
        self.inertial = {}  # body -> inverse of its base's local inertial frame
        self.geometry = {}  # target name -> (link-frame vertices, link-frame normals or None)
        for t in self.targets:
            if t.link == -1 and t.body not in self.inertial:
                self.inertial[t.body] = self.p.invertTransform(*self.p.getDynamicsInfo(t.body, -1)[3:5])
            if t.shared:
                back = Rotation.from_quat(t.orientation).inv()
                vertices = np.array(utils.vertices_from_actor(t.actor)[t.start:t.stop], dtype=np.float64)
                normals = _normals(t.actor)
                self.geometry[t.name] = (
                    back.apply(vertices - t.position),
                    None if normals is None else back.apply(np.asarray(normals[t.start:t.stop], dtype=np.float64)),
                )

    def pose(self, t):
        if t.link >= 0:
            return self.p.getLinkState(t.body, t.link, computeForwardKinematics=1)[4:6]
        com_pos, com_orn = self.p.getBasePositionAndOrientation(t.body)
        inv_pos, inv_orn = self.inertial[t.body]
        if inv_pos == (0.0, 0.0, 0.0) and inv_orn == (0.0, 0.0, 0.0, 1.0):
            return com_pos, com_orn  # skip multiplyTransforms' float32 rounding when there is no offset
        return self.p.multiplyTransforms(com_pos, com_orn, inv_pos, inv_orn)

    def __call__(self):
        touched = {}
        for t in self.targets:
            pos, orn = self.pose(t)
            rotation = Rotation.from_quat(orn)
            if t.shared:
                vertices, normals = self.geometry[t.name]
                utils.vertices_from_actor(t.actor)[t.start:t.stop] = rotation.apply(vertices) + pos
                if normals is not None:
                    _normals(t.actor)[t.start:t.stop] = rotation.apply(normals)
                touched[id(t.actor)] = t.actor
            else:
                matrix = np.eye(4)
                matrix[:3, :3] = rotation.as_matrix()
                matrix[:3, 3] = pos
                user = vtkMatrix4x4()
                user.DeepCopy(matrix.ravel())
                t.actor.SetUserMatrix(user)
        for actor in touched.values():
            _mark_modified(actor)


def vectorised_vertex_sync(world):
    """Right: a closure that rewrites every actor's vertices (whole actors too) with one einsum per actor."""
    p = world.p
    groups = defaultdict(list)
    for i, t in enumerate(world.targets):
        groups[id(t.actor)].append(i)
    plan = []
    for members in groups.values():
        actor = world.targets[members[0]].actor
        points = np.asarray(utils.vertices_from_actor(actor), dtype=np.float64)
        normals = _normals(actor)
        ranges = [(world.targets[i].start, world.targets[i].stop) for i in members]
        drawn = Rotation.from_quat([world.targets[i].orientation for i in members]).inv().as_matrix()
        local = np.stack([points[a:b] - world.targets[i].position for i, (a, b) in zip(members, ranges)])
        local = np.einsum("nij,nkj->nki", drawn, local)
        local_normals = None
        if normals is not None:
            normals = np.asarray(normals, dtype=np.float64)
            local_normals = np.einsum("nij,nkj->nki", drawn, np.stack([normals[a:b] for a, b in ranges]))
        plan.append((actor, members, ranges, local, local_normals))
    bodies = [(t.body, t.link) for t in world.targets]

    def sync():
        frames = [_link_frame_scipy(p, body, link) for body, link in bodies]
        positions = np.array([f[0] for f in frames])
        matrices = Rotation.concatenate([f[1] for f in frames]).as_matrix()
        for actor, members, ranges, local, local_normals in plan:
            moved = np.einsum("nij,nkj->nki", matrices[members], local) + positions[members][:, None, :]
            vertices = utils.vertices_from_actor(actor)
            for k, (a, b) in enumerate(ranges):
                vertices[a:b] = moved[k]
            if local_normals is not None:
                turned = np.einsum("nij,nkj->nki", matrices[members], local_normals)
                normals = _normals(actor)
                for k, (a, b) in enumerate(ranges):
                    normals[a:b] = turned[k]
            _mark_modified(actor)

    return sync


class IncrementalSync:
    """Right: turn what was drawn last frame by the motion since then, in float64, from the last drawn pose."""

    def __init__(self, world):
        self.p = world.p
        self.targets = world.targets
        self.last = {}  # target name -> (position, Rotation) it is drawn at now
        self.vertices = {}  # actor id -> float64 copy of its vertices (shared actors)
        self.normals = {}
        self.matrices = {}  # target name -> 4x4 float64 matrix of a whole actor
        for t in self.targets:
            self.last[t.name] = (np.array(t.position, dtype=np.float64), Rotation.from_quat(t.orientation))
            if t.shared and id(t.actor) not in self.vertices:
                self.vertices[id(t.actor)] = np.array(utils.vertices_from_actor(t.actor), dtype=np.float64)
                normals = _normals(t.actor)
                self.normals[id(t.actor)] = None if normals is None else np.array(normals, dtype=np.float64)
            if not t.shared:
                self.matrices[t.name] = np.eye(4)

    def __call__(self):
        touched = {}
        for t in self.targets:
            pos, rot = _link_frame_scipy(self.p, t.body, t.link)
            old_pos, old_rot = self.last[t.name]
            delta = (rot * old_rot.inv()).as_matrix()
            if t.shared:
                vertices = self.vertices[id(t.actor)]
                vertices[t.start:t.stop] = (vertices[t.start:t.stop] - old_pos) @ delta.T + pos
                utils.vertices_from_actor(t.actor)[t.start:t.stop] = vertices[t.start:t.stop]
                normals = self.normals[id(t.actor)]
                if normals is not None:
                    normals[t.start:t.stop] = normals[t.start:t.stop] @ delta.T
                    _normals(t.actor)[t.start:t.stop] = normals[t.start:t.stop]
                touched[id(t.actor)] = t.actor
            else:
                step = np.eye(4)
                step[:3, :3] = delta
                step[:3, 3] = pos - delta @ old_pos
                matrix = self.matrices[t.name] = step @ self.matrices[t.name]
                user = vtkMatrix4x4()
                user.DeepCopy(matrix.ravel())
                t.actor.SetUserMatrix(user)
            self.last[t.name] = (pos, rot)
        for actor in touched.values():
            _mark_modified(actor)


class PositionOrientationSync:
    """Right: SetPosition + SetOrientation with VTK's own Euler order (Rz·Rx·Ry, angles from as_euler('ZXY'))."""

    def __init__(self, world):
        self.p = world.p
        self.whole = [t for t in world.targets if not t.shared]
        self.shared = [t for t in world.targets if t.shared]
        self.local = {}
        for t in self.shared:
            back = np.reshape(self.p.getMatrixFromQuaternion(list(t.orientation)), (3, 3)).T
            rows = np.array(utils.vertices_from_actor(t.actor)[t.start:t.stop], dtype=np.float64)
            normals = _normals(t.actor)
            self.local[t.name] = (
                [back @ (row - t.position) for row in rows],
                None if normals is None else [back @ np.asarray(n, dtype=np.float64) for n in normals[t.start:t.stop]],
            )

    def __call__(self):
        for t in self.whole:
            pos, rot = _link_frame_scipy(self.p, t.body, t.link)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", UserWarning)  # "Gimbal lock detected": the matrix is still exact
                z, x, y = rot.as_euler("ZXY", degrees=True)
            t.actor.SetPosition(*pos)
            t.actor.SetOrientation(x, y, z)
        touched = {}
        for t in self.shared:
            pos, rot = _link_frame_scipy(self.p, t.body, t.link)
            matrix = np.reshape(self.p.getMatrixFromQuaternion(rot.as_quat().tolist()), (3, 3))
            vertices = utils.vertices_from_actor(t.actor)
            rows, normals = self.local[t.name]
            for k, row in enumerate(rows):
                vertices[t.start + k] = matrix @ row + pos
            if normals is not None:
                stored = _normals(t.actor)
                for k, normal in enumerate(normals):
                    stored[t.start + k] = matrix @ normal
            touched[id(t.actor)] = t.actor
        for actor in touched.values():
            _mark_modified(actor)


class PerTargetSync:
    """Right: a plain per-target loop with overridable steps; every mistake in ``wrong_syncs`` is this class
    with one of those steps rewritten the way users get it wrong."""

    def __init__(self, world):
        self.world = world
        self.p = world.p
        self.targets = list(world.targets)
        # Inverse of each base's local inertial frame: getBasePositionAndOrientation is the COM frame.
        self.to_link = {}
        for t in self.targets:
            if t.link == -1 and t.body not in self.to_link:
                pos, orn = self.p.getDynamicsInfo(t.body, -1)[3:5]
                back = Rotation.from_quat(orn).inv()
                self.to_link[t.body] = (-back.apply(pos), back)
        # Shared actors: the geometry of each vertex range in its link frame, captured once.
        self.local, self.local_normals = {}, {}
        for t in self.targets:
            if t.shared:
                back = Rotation.from_quat(t.orientation).inv()
                vertices = np.array(utils.vertices_from_actor(t.actor)[t.start:t.stop], dtype=np.float64)
                self.local[t.name] = back.apply(vertices - t.position)
                normals = _normals(t.actor)
                if normals is not None:
                    self.local_normals[t.name] = back.apply(np.asarray(normals[t.start:t.stop], dtype=np.float64))

    # -- the steps a mistake can hide in ---------------------------------------------------------
    def link_pose(self, t):
        """World pose (position, x-y-z-w quaternion) of the target's link frame."""
        if t.link >= 0:
            return self.p.getLinkState(t.body, t.link, computeForwardKinematics=1)[4:6]
        com_pos, com_orn = self.p.getBasePositionAndOrientation(t.body)
        offset, back = self.to_link[t.body]
        com = Rotation.from_quat(com_orn)
        return com.apply(offset) + com_pos, (com * back).as_quat()

    def matrix(self, orn) -> np.ndarray:
        """3×3 rotation matrix of a pybullet quaternion."""
        return Rotation.from_quat(orn).as_matrix()

    def to_sync(self):
        return self.targets

    def place_whole(self, t, pos, orn) -> None:
        t.actor.SetUserMatrix(_user_matrix(self.matrix(orn), pos))

    def place_shared(self, t, pos, orn) -> None:
        rotation = self.matrix(orn)
        utils.vertices_from_actor(t.actor)[t.start:t.stop] = self.local[t.name] @ rotation.T + pos
        if t.name in self.local_normals:
            _normals(t.actor)[t.start:t.stop] = self.local_normals[t.name] @ rotation.T

    def finish(self, actors) -> None:
        for actor in actors:
            utils.update_actor(actor)  # marks points and every point-data array (normals too) modified

    def draw(self, posed) -> None:
        """Place each ``(target, position, orientation)`` and finish the shared actors written."""
        touched = {}
        for t, pos, orn in posed:
            if t.shared:
                self.place_shared(t, pos, orn)
                touched[id(t.actor)] = t.actor
            else:
                self.place_whole(t, pos, orn)
        self.finish(touched.values())

    def __call__(self):
        self.draw((t, *self.link_pose(t)) for t in self.to_sync())
