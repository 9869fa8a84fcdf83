"""The kit's own sync implementation: exact, and adding as little as it can to pyBullet's own cost.

Every frame is computed from pybullet's current pose and the geometry captured once at set-up, so
nothing accumulates: frame n is as exact as frame 1.

Reading a pose from pybullet (``getBasePositionAndOrientation``, ~0.5 µs a body) is the floor no sync
can go under; ``python -m conformance bench`` measures this implementation against it. What keeps it
close to the floor:

* pybullet's functions are called directly with the client id: ``world.p`` makes a
  ``functools.partial`` per call, which costs about as much again as the read itself;
* a whole actor (one base, no inertial offset) is given one ``vtkMatrix4x4`` as its user matrix on
  the first frame, and every frame rewrites it in place: per body, one C call to read the pose, one
  to turn the quaternion into a matrix (``getMatrixFromQuaternion``, double precision in pybullet
  3.2: checked once per process, and where it is not, the vectorised path below is taken) and one
  ``DeepCopy`` of the 16 numbers, which calls ``Modified()``: the actor's matrix depends on its user
  matrix's modification time, so VTK recomputes it. Setting the same matrix again would be a no-op
  costing ~0.1 µs a body (a fifth of a pose read): the sync owns these matrices, and one replaced
  from outside is not put back;
* every other target (bodies sharing an actor, links, bases with an inertial offset) has its pose
  read into one array, its rotation matrix made in one scipy call, and a shared actor's vertices
  (and normals) computed by one batched ``matmul`` (4x faster than the equivalent ``einsum``),
  written straight into the actor's array when its targets' ranges tile one block of it (one
  fancy-index assignment otherwise).
"""

from __future__ import annotations

import itertools

import numpy as np
import pybullet
from vtkmodules.util import numpy_support
from vtkmodules.vtkCommonMath import vtkMatrix4x4

from conformance.implementations.frames import LinkFrames, SoftBodies, pybullet_matrices_are_exact, shared_actors, split
from conformance.world import Target, World

__all__ = ["ReferenceSync"]


def _points(actor) -> np.ndarray:
    return numpy_support.vtk_to_numpy(actor.GetMapper().GetInput().GetPoints().GetData())


def _normals(actor) -> np.ndarray | None:
    normals = actor.GetMapper().GetInput().GetPointData().GetNormals()
    return None if normals is None else numpy_support.vtk_to_numpy(normals)


def _modified(actor, normals: bool) -> None:
    data = actor.GetMapper().GetInput()
    data.GetPoints().Modified()
    if normals:
        data.GetPointData().GetNormals().Modified()


class ReferenceSync:
    """Exact, vectorised sync: world vertices = pybullet link-frame pose × geometry captured at set-up."""

    #: What draws the soft bodies' targets (a subclass may draw them otherwise).
    soft_bodies = SoftBodies

    def __init__(self, world: World, targets: tuple[Target, ...] | None = None):
        self.p, self.client = world.p, world.client
        self.targets = tuple(world.targets if targets is None else targets)
        # Direct: whole actors of bases whose link frame is their centre of mass (three C calls a body).
        # A subclass drawing poses of its own (overriding _poses) gets every target through it instead.
        direct, rest, inertial = split(self.client, self.targets, pybullet_matrices_are_exact() and type(self)._poses is ReferenceSync._poses)
        self._direct_bodies = [t.body for t in direct]
        self._direct_matrices = [vtkMatrix4x4() for _ in direct]
        self._frames = LinkFrames(self.client, tuple(rest), inertial) if rest else None
        self._whole = [(i, vtkMatrix4x4()) for i, t in enumerate(rest) if not t.shared]
        #: (actor, matrix) pairs whose matrix becomes the actor's user matrix on the first frame.
        self._unattached = list(zip([t.actor for t in direct], self._direct_matrices))
        self._unattached += [(rest[i].actor, matrix) for i, matrix in self._whole]
        self._shared = shared_actors(rest, _points, _normals, _modified)
        soft = [t for t in self.targets if t.nodes is not None]
        self._soft = self.soft_bodies(self.client, soft, _points, _modified) if soft else None

    def _poses(self) -> tuple[np.ndarray, np.ndarray]:
        """Link-frame positions ``(n, 3)`` and rotation matrices ``(n, 3, 3)`` of the targets drawn from
        arrays, in ``self.targets`` order. A subclass may override it to draw other poses (it then gets
        *every* target, the whole-actor fast path being off) and call it through ``super()``."""
        return self._frames()

    def __call__(self) -> None:
        if self._soft is not None:
            self._soft()
        copy = vtkMatrix4x4.DeepCopy  # (matrix, 16 numbers): sets them and calls Modified()
        if self._direct_bodies:
            rotation = pybullet.getMatrixFromQuaternion
            # Read first, all at once (map iterates in C), then one loop of two C calls per body.
            poses = list(map(pybullet.getBasePositionAndOrientation, self._direct_bodies, itertools.repeat(self.client)))
            for ((x, y, z), orientation), matrix in zip(poses, self._direct_matrices):
                r0, r1, r2, r3, r4, r5, r6, r7, r8 = rotation(orientation)
                copy(matrix, (r0, r1, r2, x, r3, r4, r5, y, r6, r7, r8, z, 0.0, 0.0, 0.0, 1.0))
        if self._frames is not None:
            positions, matrices = self._poses()
            for shared in self._shared:
                shared(positions, matrices)
            if self._whole:
                rows = [i for i, _ in self._whole]
                elements = np.zeros((len(rows), 4, 4))
                elements[:, :3, :3], elements[:, :3, 3], elements[:, 3, 3] = matrices[rows], positions[rows], 1.0
                for (_, matrix), values in zip(self._whole, elements.reshape(-1, 16).tolist()):
                    copy(matrix, values)
        if self._unattached:
            for actor, matrix in self._unattached:
                actor.SetUserMatrix(matrix)
            self._unattached = []
