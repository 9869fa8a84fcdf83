"""Correct sync implementations on FURY 0.12 (VTK), each written in its own style, that the kit must accept.

They are what a careful user might write, not copies of the kit's reference: each computes the
world pose of every target's *link frame* (a base: the centre-of-mass pose from
``getBasePositionAndOrientation`` composed with the inverse of the base's local inertial frame,
``getDynamicsInfo(body, -1)[3:5]``; a link: ``getLinkState(..., computeForwardKinematics=1)[4:6]``),
moves whole actors and the vertex ranges of shared actors there, turns stored vertex normals with
them, and marks what it wrote as modified so that VTK draws it. A soft body (``Target.nodes``) has no
pose: each copies its simulated nodes (``getMeshData(..., flags=MESH_DATA_SIMULATION_MESH)``) into its
actor's vertices, each in its own way, and leaves the actor's transform the identity.

This file holds what touches a FURY 0.12 actor; each class's renderer-free steps (poses, link-frame
geometry, the arithmetic of a range rewrite) are its base in ``sync_steps``, shared with the FURY 2
counterparts in ``right_syncs_pygfx``; ``right_syncs`` picks this module or that one.

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
* :class:`PerTargetSync` — the plainest loop: a pose per target (pybullet's matrix, scipy for a base's inertial offset), user matrix or vertex rewrite,
  ``fury.utils.update_actor``; each method is a step that ``wrong_syncs`` gets wrong in one way.
"""

from __future__ import annotations

import weakref

from fury import utils
from vtkmodules.util import numpy_support
from vtkmodules.vtkCommonMath import vtkMatrix4x4

import sync_steps

__all__ = ["IncrementalSync", "PerTargetSync", "PositionOrientationSync", "UserMatrixSync", "vectorised_vertex_sync"]


def _user_matrix(matrix) -> vtkMatrix4x4:
    """A 4x4 numpy matrix as VTK's."""
    user = vtkMatrix4x4()
    user.DeepCopy(matrix.ravel())
    return user


_VIEWS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _vertex_view(actor):
    """``utils.vertices_from_actor(actor)``, made once per points array the actor holds: a view of VTK's
    points stays the points while the actor keeps them (FURY's decorator on it inspects the call's
    signature every time, which a sync written for speed does not pay a target a frame)."""
    points = actor.GetMapper().GetInput().GetPoints()
    kept = _VIEWS.get(actor)
    if kept is None or kept[0] is not points:
        kept = _VIEWS[actor] = (points, utils.vertices_from_actor(actor))
    return kept[1]


class _Arrays(sync_steps.ActorArrays):
    """Where a FURY 0.12 actor keeps its vertices and normals: its polydata's arrays, seen through numpy,
    which VTK draws again only once they are marked ``Modified()``."""

    vertex_view = staticmethod(_vertex_view)

    @staticmethod
    def normal_view(actor):
        """The actor's stored vertex normals as a writable view, or None (VTK derives them from faces)."""
        array = actor.GetMapper().GetInput().GetPointData().GetNormals()
        return None if array is None else numpy_support.vtk_to_numpy(array)

    @staticmethod
    def announce(actor) -> None:
        data = actor.GetMapper().GetInput()
        data.GetPoints().Modified()
        if data.GetPointData().GetNormals() is not None:
            data.GetPointData().GetNormals().Modified()


class UserMatrixSync(_Arrays, sync_steps.UserMatrixSteps):
    """Right: per-actor user matrices; per-target vertex rewrite (and normals) for shared actors."""

    def __call__(self):
        touched, read = {}, {}
        for t in self.targets:
            if t.nodes is not None:
                self.copy_nodes(t, read)
                touched[id(t.actor)] = t.actor
                continue
            pos, orn = self.pose(t)
            if t.shared:
                self.move_range(t, pos, orn)
                touched[id(t.actor)] = t.actor
            else:
                t.actor.SetUserMatrix(_user_matrix(self.whole_matrix(pos, orn)))
        for actor in touched.values():
            self.announce(actor)


def vectorised_vertex_sync(world):
    """Right: a closure that rewrites every actor's vertices (whole actors too) with one einsum per actor."""
    return sync_steps.vectorised_vertex_sync(world, _Arrays)


class IncrementalSync(_Arrays, sync_steps.IncrementalSteps):
    """Right: turn what was drawn last frame by the motion since then, in float64, from the last drawn pose."""

    def __call__(self):
        touched = {}
        for t in self.targets:
            if t.nodes is not None:
                self.refresh_nodes(t)
                touched[id(t.actor)] = t.actor
            elif t.shared:
                self.turn_range(t)
                touched[id(t.actor)] = t.actor
            else:
                t.actor.SetUserMatrix(_user_matrix(self.turn_whole(t)))
        for actor in touched.values():
            self.announce(actor)


class PositionOrientationSync(_Arrays, sync_steps.PositionOrientationSteps):
    """Right: SetPosition + SetOrientation with VTK's own Euler order (Rz·Rx·Ry, angles from as_euler('ZXY'))."""

    def place_whole(self, t, pos, rot):
        z, x, y = sync_steps.euler_angles(rot, "ZXY", degrees=True)
        t.actor.SetPosition(*pos)
        t.actor.SetOrientation(x, y, z)


class PerTargetSync(_Arrays, sync_steps.PerTargetSteps):
    """Right: a plain per-target loop with overridable steps; every mistake in ``wrong_syncs`` is this class
    with one of those steps rewritten the way users get it wrong."""

    def place_whole(self, t, pos, orn) -> None:
        t.actor.SetUserMatrix(_user_matrix(sync_steps.pose_matrix(self.matrix(orn), pos)))

    def finish(self, actors) -> None:
        for actor in actors:
            utils.update_actor(actor)  # marks points and every point-data array (normals too) modified
