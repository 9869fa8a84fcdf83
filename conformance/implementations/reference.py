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

import functools
import itertools
from collections import defaultdict

import numpy as np
import pybullet
from scipy.spatial.transform import Rotation
from vtkmodules.util import numpy_support
from vtkmodules.vtkCommonMath import vtkMatrix4x4

from conformance.world import Target, World

__all__ = ["ReferenceSync"]

_IDENTITY_FRAME = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))
_flatten = itertools.chain.from_iterable


def _points(actor) -> np.ndarray:
    return numpy_support.vtk_to_numpy(actor.GetMapper().GetInput().GetPoints().GetData())


def _normals(actor) -> np.ndarray | None:
    normals = actor.GetMapper().GetInput().GetPointData().GetNormals()
    return None if normals is None else numpy_support.vtk_to_numpy(normals)


@functools.lru_cache(maxsize=None)
def _pybullet_matrices_are_exact() -> bool:
    """Whether ``getMatrixFromQuaternion`` gives scipy's rotation matrices to double precision (1e-12)
    for random unit quaternions: true of pybullet 3.2.7 (measured: 8e-16); a build that computed
    them in float32 (errors ~1e-7) would make the whole-actor fast path inexact, so it is not used."""
    quaternions = np.random.default_rng(0).normal(size=(64, 4))
    quaternions /= np.linalg.norm(quaternions, axis=1, keepdims=True)
    theirs = np.array([pybullet.getMatrixFromQuaternion(q) for q in quaternions.tolist()]).reshape(-1, 3, 3)
    return bool(np.abs(theirs - Rotation.from_quat(quaternions).as_matrix()).max() <= 1e-12)


class _LinkFrames:
    """Link-frame poses of many targets at once: positions ``(n, 3)`` and rotation matrices ``(n, 3, 3)``.

    A base's link frame is its centre-of-mass frame (``getBasePositionAndOrientation``) times the
    inverse of its local inertial frame (``getDynamicsInfo[3:5]``), composed only where that is not
    the identity; a link's is ``getLinkStates(..., computeForwardKinematics=1)[4:6]``, one call per body.
    """

    def __init__(self, client: int, targets: tuple[Target, ...], inertial: dict):
        self.client, self.count = client, len(targets)
        self.bases = [i for i, t in enumerate(targets) if t.link == -1]
        self.base_bodies = [targets[i].body for i in self.bases]
        self.only_bases = len(self.bases) == self.count
        offset = [k for k, i in enumerate(self.bases) if inertial[targets[i].body] != _IDENTITY_FRAME]
        self.offset = np.array(offset, dtype=np.intp)
        if offset:
            frames = [inertial[self.base_bodies[k]] for k in offset]
            inverse = Rotation.from_quat([orn for _, orn in frames]).inv()
            self.offset_rotation = inverse
            self.offset_position = -inverse.apply(np.array([pos for pos, _ in frames], dtype=np.float64))
        links = defaultdict(list)
        for i, t in enumerate(targets):
            if t.link >= 0:
                links[t.body].append((i, t.link))
        self.links = []
        for body, rows in links.items():
            ids = sorted({link for _, link in rows})
            self.links.append((body, ids, [(i, ids.index(link)) for i, link in rows]))

    def __call__(self) -> tuple[np.ndarray, np.ndarray]:
        if self.only_bases:
            positions, orientations = self._bases()
        else:
            positions, orientations = np.empty((self.count, 3)), np.empty((self.count, 4))
            if self.bases:
                positions[self.bases], orientations[self.bases] = self._bases()
            for body, ids, rows in self.links:
                states = pybullet.getLinkStates(body, ids, computeForwardKinematics=1, physicsClientId=self.client)
                for i, k in rows:
                    positions[i], orientations[i] = states[k][4], states[k][5]
        return positions, Rotation.from_quat(orientations).as_matrix()

    def _bases(self) -> tuple[np.ndarray, np.ndarray]:
        # Streamed into one array, 7 numbers a body: the fastest way measured from pybullet's nested
        # tuples to an array (a list then np.array: 1.2-1.3x slower; structured dtypes, zip: ~2x).
        poses = map(pybullet.getBasePositionAndOrientation, self.base_bodies, itertools.repeat(self.client))
        flat = np.fromiter(_flatten(_flatten(poses)), dtype=np.float64, count=7 * len(self.base_bodies)).reshape(-1, 7)
        positions, orientations = flat[:, :3], flat[:, 3:]
        if len(self.offset):
            centre = Rotation.from_quat(orientations[self.offset])
            positions[self.offset] = positions[self.offset] + centre.apply(self.offset_position)
            orientations[self.offset] = (centre * self.offset_rotation).as_quat()
        return positions, orientations


class _SharedActor:
    """One actor drawing several targets: their link-frame geometry, and where in the actor it goes."""

    def __init__(self, actor, rows: list[int], targets: list[Target]):
        self.actor = actor
        # Rows of the pose arrays: a slice when consecutive, so that picking them copies nothing.
        consecutive = rows == list(range(rows[0], rows[0] + len(rows)))
        self.rows = slice(rows[0], rows[-1] + 1) if consecutive else np.array(rows, dtype=np.intp)
        # Geometry in the link frame, recovered once from the vertices as drawn at set-up.
        points = np.asarray(_points(actor), dtype=np.float64)
        undo = [Rotation.from_quat(t.orientation) for t in targets]
        self.local = np.stack([u.inv().apply(points[t.start:t.stop] - t.position) for u, t in zip(undo, targets)])
        normals = _normals(actor)
        self.local_normals = None if normals is None else np.stack([
            np.asarray(normals[t.start:t.stop], dtype=np.float64) @ u.as_matrix()  # row vectors: × R = R⁻¹ applied
            for u, t in zip(undo, targets)
        ])
        # Where the vertices go: one block of the array when the ranges tile it in order, else an index.
        tiled = all(a.stop == b.start for a, b in zip(targets, targets[1:]))
        self.block = slice(targets[0].start, targets[-1].stop) if tiled else None
        self.index = None if tiled else np.concatenate([np.arange(t.start, t.stop) for t in targets])

    def __call__(self, positions: np.ndarray, matrices: np.ndarray) -> None:
        rotations = matrices[self.rows]
        data = self.actor.GetMapper().GetInput()
        self._write(_points(self.actor), rotations, self.local, positions[self.rows])
        data.GetPoints().Modified()
        if self.local_normals is not None:
            self._write(_normals(self.actor), rotations, self.local_normals, None)
            data.GetPointData().GetNormals().Modified()

    def _write(self, array: np.ndarray, rotations: np.ndarray, local: np.ndarray, positions) -> None:
        """``array`` rows of the targets = rotations × local (+ positions), each vertex as a row."""
        if self.block is not None and array.dtype == np.float64:
            # Straight into the actor's own array: no temporary the size of the vertices.
            out = array[self.block].reshape(local.shape)
            np.matmul(local, rotations.transpose(0, 2, 1), out=out)
            if positions is not None:
                out += positions[:, None, :]
            return
        moved = np.matmul(local, rotations.transpose(0, 2, 1))
        if positions is not None:
            moved += positions[:, None, :]
        if self.block is not None:
            array[self.block] = moved.reshape(-1, 3)  # one rounding to the array's type (float32 for spheres)
        else:
            array[self.index] = moved.reshape(-1, 3)


class ReferenceSync:
    """Exact, vectorised sync: world vertices = pybullet link-frame pose × geometry captured at set-up."""

    def __init__(self, world: World, targets: tuple[Target, ...] | None = None):
        self.p, self.client = world.p, world.client
        self.targets = tuple(world.targets if targets is None else targets)
        inertial = {}
        for t in self.targets:
            if t.link == -1 and t.body not in inertial:
                info = pybullet.getDynamicsInfo(t.body, -1, physicsClientId=self.client)
                inertial[t.body] = (tuple(info[3]), tuple(info[4]))
        # Direct: whole actors of bases whose link frame is their centre of mass (three C calls a body).
        # A subclass drawing poses of its own (overriding _poses) gets every target through it instead.
        fast = _pybullet_matrices_are_exact() and type(self)._poses is ReferenceSync._poses

        def is_direct(t: Target) -> bool:
            return fast and not t.shared and t.link == -1 and inertial[t.body] == _IDENTITY_FRAME

        direct = [t for t in self.targets if is_direct(t)]
        rest = [t for t in self.targets if not is_direct(t)]
        self._direct_bodies = [t.body for t in direct]
        self._direct_matrices = [vtkMatrix4x4() for _ in direct]
        self._frames = _LinkFrames(self.client, tuple(rest), inertial) if rest else None
        self._whole = [(i, vtkMatrix4x4()) for i, t in enumerate(rest) if not t.shared]
        #: (actor, matrix) pairs whose matrix becomes the actor's user matrix on the first frame.
        self._unattached = list(zip([t.actor for t in direct], self._direct_matrices))
        self._unattached += [(rest[i].actor, matrix) for i, matrix in self._whole]
        by_actor: dict[int, list[int]] = defaultdict(list)
        for i, t in enumerate(rest):
            if t.shared:
                by_actor[id(t.actor)].append(i)
        self._shared = [_SharedActor(rest[rows[0]].actor, rows, [rest[i] for i in rows]) for rows in by_actor.values()]

    def _poses(self) -> tuple[np.ndarray, np.ndarray]:
        """Link-frame positions ``(n, 3)`` and rotation matrices ``(n, 3, 3)`` of the targets drawn from
        arrays, in ``self.targets`` order. A subclass may override it to draw other poses (it then gets
        *every* target, the whole-actor fast path being off) and call it through ``super()``."""
        return self._frames()

    def __call__(self) -> None:
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
