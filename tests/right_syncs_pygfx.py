"""Correct sync implementations on FURY 2 (pygfx), each written in its own style, that the kit must accept.

They are what a careful user might write, not copies of the kit's reference: each computes the
world pose of every target's *link frame* (a base: the centre-of-mass pose from
``getBasePositionAndOrientation`` composed with the inverse of the base's local inertial frame,
``getDynamicsInfo(body, -1)[3:5]``; a link: ``getLinkState(..., computeForwardKinematics=1)[4:6]``),
moves whole actors and the vertex ranges of shared actors there, turns stored vertex normals with
them (``geometry.normals``, which FURY 2's smooth spheres have), and announces what it wrote with
the buffer's ``update_range``/``update_full`` so that pygfx uploads it (without, the GPU keeps the old
vertices). A soft body (``Target.nodes``) has no pose: each copies its simulated nodes
(``getMeshData(..., flags=MESH_DATA_SIMULATION_MESH)``) into its actor's positions, each in its own
way, and leaves the actor's ``local`` transform the identity.

This file holds what touches a FURY 2 actor; each class's renderer-free steps (poses, link-frame
geometry, the arithmetic of a range rewrite) are its base in ``sync_steps``, shared with the FURY 0.12
counterparts in ``right_syncs_vtk``; ``right_syncs`` picks this module or that one.

* :class:`UserMatrixSync` — FURY 2 has no user matrix: one 4x4 ``actor.local.matrix`` per whole
  actor, a per-target vertex rewrite (announced with ``update_range``) for shared actors; pybullet's
  own ``multiplyTransforms``/``invertTransform`` for the base offset.
* :func:`vectorised_vertex_sync` — a closure (not a class) that rewrites the vertices of *every*
  actor, whole ones too, with one ``numpy.einsum`` per actor and leaves every actor transform alone.
* :class:`IncrementalSync` — the guide's incremental idea done in float64: each frame turns what it
  drew last time by the rotation since then (``R_new · R_old⁻¹``, scipy), for whole actors as well
  as vertex ranges, keeping its own float64 copy so that rounding does not pile up in the float32
  ``positions`` buffer.
* :class:`PositionOrientationSync` — ``actor.local.position`` + ``actor.local.euler`` with the
  Euler angles pygfx actually uses: ``local.euler = (x, y, z)`` is ``pylinalg.quat_from_euler((x, y,
  z))``, whose default order ``"xyz"`` is lowercase, i.e. extrinsic (about the fixed axes, x first),
  so it builds ``Rz(z)·Ry(y)·Rx(x)`` in radians, and the angles come from ``Rotation.as_euler("xyz")``
  (pybullet's getEulerFromQuaternion convention, in float64); pybullet's matrices for shared actors,
  row by row in a Python loop.
* :class:`PerTargetSync` — the plainest loop: a pose per target (pybullet's matrix, scipy for a base's inertial offset), ``local.matrix`` or vertex
  rewrite, ``update_full()``; each method is a step that ``wrong_syncs`` gets wrong in one way.
"""

from __future__ import annotations

import sync_steps

__all__ = ["IncrementalSync", "PerTargetSync", "PositionOrientationSync", "UserMatrixSync", "vectorised_vertex_sync"]


class _Arrays(sync_steps.ActorArrays):
    """Where a FURY 2 actor keeps its vertices and normals: its geometry's buffers, which pygfx uploads
    again only when told, with ``update_full`` or (for part of one) ``update_range``."""

    @staticmethod
    def vertex_view(actor):
        """The actor's vertices as a writable float32 view (FURY 2 has no ``utils.vertices_from_actor``)."""
        return actor.geometry.positions.data

    @staticmethod
    def normal_view(actor):
        """The actor's stored vertex normals as a writable view, or None (pygfx derives them from faces)."""
        normals = getattr(actor.geometry, "normals", None)
        return None if normals is None else normals.data

    @staticmethod
    def announce(actor) -> None:
        actor.geometry.positions.update_full()
        if getattr(actor.geometry, "normals", None) is not None:
            actor.geometry.normals.update_full()

    @staticmethod
    def announce_range(t) -> None:
        """Announce the vertices (and normals) of a shared target's range alone."""
        t.actor.geometry.positions.update_range(t.start, t.stop - t.start)
        if getattr(t.actor.geometry, "normals", None) is not None:
            t.actor.geometry.normals.update_range(t.start, t.stop - t.start)


class UserMatrixSync(_Arrays, sync_steps.UserMatrixSteps):
    """Right: per-actor ``local.matrix`` (FURY 2's user matrix); per-target vertex rewrite (and normals)
    for shared actors, each range announced with ``update_range``."""

    def __call__(self):
        read = {}
        for t in self.targets:
            if t.nodes is not None:
                self.copy_nodes(t, read)
                self.announce_range(t)
                continue
            pos, orn = self.pose(t)
            if t.shared:
                self.move_range(t, pos, orn)
                self.announce_range(t)  # only this target's range goes to the GPU
            else:
                t.actor.local.matrix = self.whole_matrix(pos, orn)  # absolute: replaces position, rotation and scale


def vectorised_vertex_sync(world):
    """Right: a closure that rewrites every actor's vertices (whole actors too) with one einsum per actor."""
    return sync_steps.vectorised_vertex_sync(world, _Arrays)


class IncrementalSync(_Arrays, sync_steps.IncrementalSteps):
    """Right: turn what was drawn last frame by the motion since then, in float64, from the last drawn pose."""

    def __call__(self):
        for t in self.targets:
            if t.nodes is not None:
                self.refresh_nodes(t)
                self.announce_range(t)
            elif t.shared:
                self.turn_range(t)
                self.announce_range(t)
            else:
                # FURY's own actor.rotate/translate compose the same way (step @ local.matrix), but
                # through a float32 step; the float64 copy here keeps the product exact.
                t.actor.local.matrix = self.turn_whole(t)


class PositionOrientationSync(_Arrays, sync_steps.PositionOrientationSteps):
    """Right: local.position + local.euler with pygfx's own Euler order (extrinsic x-y-z, Rz·Ry·Rx, angles from as_euler('xyz'))."""

    def place_whole(self, t, pos, rot):
        x, y, z = sync_steps.euler_angles(rot, "xyz")  # radians, as local.euler takes them (FURY's actor.rotate takes degrees)
        t.actor.local.position = pos
        t.actor.local.euler = (x, y, z)


class PerTargetSync(_Arrays, sync_steps.PerTargetSteps):
    """Right: a plain per-target loop with overridable steps; every mistake in ``wrong_syncs`` is this class
    with one of those steps rewritten the way users get it wrong."""

    def place_whole(self, t, pos, orn) -> None:
        t.actor.local.matrix = sync_steps.pose_matrix(self.matrix(orn), pos)

    def finish(self, actors) -> None:
        for actor in actors:
            self.announce(actor)  # positions.update_full(), and normals.update_full() where there are normals
