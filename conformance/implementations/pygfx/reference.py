"""The kit's own sync implementation on FURY 2: exact, and adding as little as it can to pyBullet's cost.

The same method as on FURY 0.12 (:mod:`conformance.implementations.vtk.reference`): every frame is
computed from pybullet's current pose and the geometry captured once at set-up, so nothing accumulates.

* a whole actor (one base, no inertial offset) gets pybullet's pose as its local transform in one
  call, ``actor.local.components = (position, orientation, None)``: pygfx takes pybullet's (x, y, z)
  and (x, y, z, w) as they are, keeps the scale (None) and composes the matrix in float64. (One setter
  flags one update; ``position`` then ``rotation`` cost 1.3 times as much, and ``local.matrix = M``
  about 20 times: pygfx decomposes every matrix it is given back into those components.)
* every other target (bodies sharing an actor, links, bases with an inertial offset) has its pose read
  into one array (:class:`~conformance.implementations.frames.LinkFrames`); a whole actor of those
  gets its link-frame pose the same way (the quaternions from one scipy call), a shared actor has its
  vertex ranges (and normals) recomputed by one batched ``matmul`` into ``geometry.positions.data`` and
  announced with ``update_full()``, without which pygfx keeps drawing the old vertices.
"""

from __future__ import annotations

import itertools

import numpy as np
import pybullet
from scipy.spatial.transform import Rotation

from conformance.implementations.frames import LinkFrames, SoftBodies, shared_actors, split
from conformance.world import Target, World

__all__ = ["ReferenceSync"]


def _points(actor) -> np.ndarray:
    return actor.geometry.positions.data


def _normals(actor) -> np.ndarray | None:
    normals = getattr(actor.geometry, "normals", None)
    return None if normals is None else normals.data


def _announce(actor, normals: bool) -> None:
    actor.geometry.positions.update_full()
    if normals:
        actor.geometry.normals.update_full()


class ReferenceSync:
    """Exact, vectorised sync: world vertices = pybullet link-frame pose × geometry captured at set-up."""

    #: What draws the soft bodies' targets (a subclass may draw them otherwise).
    soft_bodies = SoftBodies

    def __init__(self, world: World, targets: tuple[Target, ...] | None = None):
        self.p, self.client = world.p, world.client
        self.targets = tuple(world.targets if targets is None else targets)
        # Direct: whole actors of bases whose link frame is their centre of mass.
        # A subclass drawing poses of its own (overriding _poses) gets every target through it instead.
        direct, rest, inertial = split(self.client, self.targets, type(self)._poses is ReferenceSync._poses)
        self._direct_bodies = [t.body for t in direct]
        self._direct_transforms = [t.actor.local for t in direct]
        self._frames = LinkFrames(self.client, tuple(rest), inertial) if rest else None
        self._whole = [(i, t.actor) for i, t in enumerate(rest) if not t.shared]
        self._shared = shared_actors(rest, _points, _normals, _announce)
        soft = [t for t in self.targets if t.nodes is not None]
        self._soft = self.soft_bodies(self.client, soft, _points, _announce) if soft else None

    def _poses(self) -> tuple[np.ndarray, np.ndarray]:
        """Link-frame positions ``(n, 3)`` and rotation matrices ``(n, 3, 3)`` of the targets drawn from
        arrays, in ``self.targets`` order. A subclass may override it to draw other poses (it then gets
        *every* target, the whole-actor fast path being off) and call it through ``super()``."""
        return self._frames()

    def __call__(self) -> None:
        if self._soft is not None:
            self._soft()
        if self._direct_bodies:
            poses = map(pybullet.getBasePositionAndOrientation, self._direct_bodies, itertools.repeat(self.client))
            for pose, transform in zip(poses, self._direct_transforms):
                transform.components = (*pose, None)
        if self._frames is not None:
            positions, matrices = self._poses()
            for shared in self._shared:
                shared(positions, matrices)
            if self._whole:
                rows = [i for i, _ in self._whole]
                quaternions = Rotation.from_matrix(matrices[rows]).as_quat()
                for (_, actor), position, orientation in zip(self._whole, positions[rows], quaternions):
                    actor.local.components = (position, orientation, None)
