"""What the kit's reference syncs share on both backends: link-frame poses of many targets read at
once, and a shared actor's vertex ranges recomputed from the geometry captured at set-up.

Nothing here touches a renderer: a backend's reference sync hands in views of an actor's arrays and
how to announce that they changed.
"""

from __future__ import annotations

import functools
import itertools
from collections import defaultdict
from typing import Any, Callable

import numpy as np
import pybullet
from scipy.spatial.transform import Rotation

from conformance.world import Target

__all__ = ["IDENTITY_FRAME", "LinkFrames", "SharedActor", "SoftBodies", "inertial_frames", "pybullet_matrices_are_exact",
           "shared_actors", "split"]

IDENTITY_FRAME = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))
_flatten = itertools.chain.from_iterable


@functools.lru_cache(maxsize=None)
def pybullet_matrices_are_exact() -> bool:
    """Whether ``getMatrixFromQuaternion`` gives scipy's rotation matrices to double precision (1e-12)
    for random unit quaternions: true of pybullet 3.2.7 (measured: 8e-16); a build that computed
    them in float32 (errors ~1e-7) would make a whole-actor fast path inexact, so it is not used."""
    quaternions = np.random.default_rng(0).normal(size=(64, 4))
    quaternions /= np.linalg.norm(quaternions, axis=1, keepdims=True)
    theirs = np.array([pybullet.getMatrixFromQuaternion(q) for q in quaternions.tolist()]).reshape(-1, 3, 3)
    return bool(np.abs(theirs - Rotation.from_quat(quaternions).as_matrix()).max() <= 1e-12)


def inertial_frames(client: int, targets) -> dict[int, tuple]:
    """Each base's local inertial frame ``(position, orientation)`` (``getDynamicsInfo[3:5]``), by body."""
    inertial = {}
    for t in targets:
        if t.link == -1 and t.body not in inertial:
            info = pybullet.getDynamicsInfo(t.body, -1, physicsClientId=client)
            inertial[t.body] = (tuple(info[3]), tuple(info[4]))
    return inertial


class LinkFrames:
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
        offset = [k for k, i in enumerate(self.bases) if inertial[targets[i].body] != IDENTITY_FRAME]
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


class SharedActor:
    """One actor drawing several targets: their link-frame geometry, and where in the actor it goes."""

    def __init__(self, actor, rows: list[int], targets: list[Target], points: Callable[[Any], np.ndarray],
                 normals: Callable[[Any], np.ndarray | None], announce: Callable[[Any, bool], None]):
        """``points``/``normals`` are writable views of the actor's arrays, ``announce(actor, normals)``
        tells the renderer the vertices (and the normals, when the second argument is true) changed."""
        self.actor = actor
        self._points, self._normals_of, self._announce = points, normals, announce
        # Rows of the pose arrays: a slice when consecutive, so that picking them copies nothing.
        consecutive = rows == list(range(rows[0], rows[0] + len(rows)))
        self.rows = slice(rows[0], rows[-1] + 1) if consecutive else np.array(rows, dtype=np.intp)
        # Geometry in the link frame, recovered once from the vertices as drawn at set-up.
        points = np.asarray(points(actor), dtype=np.float64)
        undo = [Rotation.from_quat(t.orientation) for t in targets]
        self.local = np.stack([u.inv().apply(points[t.start:t.stop] - t.position) for u, t in zip(undo, targets)])
        normals = self._normals_of(actor)
        self.local_normals = None if normals is None else np.stack([
            np.asarray(normals[t.start:t.stop], dtype=np.float64) @ u.as_matrix()  # row vectors: × R = R⁻¹ applied
            for u, t in zip(undo, targets)
        ])
        # Where the vertices go: one block of the array, since the backends lay out a shared actor's bodies
        # one after another in the targets' order (backends/common.py), and every one of them is here
        # (a shared target is never posed directly).
        self.block = slice(targets[0].start, targets[-1].stop)

    def __call__(self, positions: np.ndarray, matrices: np.ndarray) -> None:
        rotations = matrices[self.rows]
        self._write(self._points(self.actor), rotations, self.local, positions[self.rows])
        if self.local_normals is not None:
            self._write(self._normals_of(self.actor), rotations, self.local_normals, None)
        self._announce(self.actor, self.local_normals is not None)

    def _write(self, array: np.ndarray, rotations: np.ndarray, local: np.ndarray, positions) -> None:
        """``array`` rows of the targets = rotations × local (+ positions), each vertex as a row."""
        if array.dtype == np.float64:
            # Straight into the actor's own array: no temporary the size of the vertices.
            out = array[self.block].reshape(local.shape)
            np.matmul(local, rotations.transpose(0, 2, 1), out=out)
            if positions is not None:
                out += positions[:, None, :]
            return
        moved = np.matmul(local, rotations.transpose(0, 2, 1))
        if positions is not None:
            moved += positions[:, None, :]
        array[self.block] = moved.reshape(-1, 3)  # one rounding to the array's type (float32)


class SoftBodies:
    """The soft bodies' targets (``Target.nodes``): each frame, every soft body's simulated nodes read once
    (``getMeshData(body, -1, flags=MESH_DATA_SIMULATION_MESH)``) and copied into its vertices, announced."""

    def __init__(self, client: int, targets: list[Target], points: Callable[[Any], np.ndarray],
                 announce: Callable[[Any, bool], None]):
        self.client, self.targets, self._points, self._announce = client, targets, points, announce

    def __call__(self) -> None:
        read: dict[int, np.ndarray] = {}
        for t in self.targets:
            if t.body not in read:
                nodes = pybullet.getMeshData(t.body, -1, flags=pybullet.MESH_DATA_SIMULATION_MESH,
                                             physicsClientId=self.client)[1]
                read[t.body] = np.asarray(nodes, dtype=np.float64)
            self._points(t.actor)[t.start:t.stop] = self.vertices(t, read[t.body])
            self._announce(t.actor, False)

    def vertices(self, t: Target, nodes: np.ndarray) -> np.ndarray:
        """What target ``t``'s vertices become, given its body's ``nodes`` now: the nodes it follows."""
        return nodes[t.nodes]


def split(client: int, targets: tuple[Target, ...], direct_allowed: bool) -> tuple[list, list, dict]:
    """``(direct, rest, inertial)``: the rigid targets a reference sync poses straight from
    ``getBasePositionAndOrientation`` (whole actors of bases whose link frame is their centre of mass,
    when ``direct_allowed``), every other rigid target, and each base's inertial frame. Soft bodies'
    targets are in neither (:class:`SoftBodies` draws them)."""
    targets = tuple(t for t in targets if t.nodes is None)
    inertial = inertial_frames(client, targets)

    def is_direct(t: Target) -> bool:
        return direct_allowed and not t.shared and t.link == -1 and inertial[t.body] == IDENTITY_FRAME

    return [t for t in targets if is_direct(t)], [t for t in targets if not is_direct(t)], inertial


def shared_actors(rest: list[Target], points, normals, announce) -> list[SharedActor]:
    """A :class:`SharedActor` for each actor that ``rest``'s shared targets live in (rows of ``rest``)."""
    by_actor: dict[int, list[int]] = defaultdict(list)
    for i, t in enumerate(rest):
        if t.shared:
            by_actor[id(t.actor)].append(i)
    return [SharedActor(rest[rows[0]].actor, rows, [rest[i] for i in rows], points, normals, announce)
            for rows in by_actor.values()]
