"""The kit's own sync implementation: exact and vectorised.

Every frame is computed from pybullet's current pose and the geometry captured once at set-up, so
nothing accumulates: frame n is as exact as frame 1. Poses of all targets are fetched in one pass
(``getLinkStates`` per body for links), turned into rotation matrices in one scipy call, and each
shared actor's vertices are rewritten with one ``einsum``. Whole actors get a user matrix.
"""

from __future__ import annotations

from collections import defaultdict

import numpy as np
from vtkmodules.vtkCommonMath import vtkMatrix4x4
from scipy.spatial.transform import Rotation
from vtkmodules.util import numpy_support

from conformance.world import Target, World

__all__ = ["ReferenceSync"]


def _points(actor) -> np.ndarray:
    return numpy_support.vtk_to_numpy(actor.GetMapper().GetInput().GetPoints().GetData())


def _normals(actor) -> np.ndarray | None:
    normals = actor.GetMapper().GetInput().GetPointData().GetNormals()
    return None if normals is None else numpy_support.vtk_to_numpy(normals)


class ReferenceSync:
    """Exact, vectorised sync: world vertices = pybullet link-frame pose × geometry captured at set-up."""

    def __init__(self, world: World, targets: tuple[Target, ...] | None = None):
        self.p = world.p
        self.targets = tuple(world.targets if targets is None else targets)
        # Base link frame = centre-of-mass frame × inverse(local inertial frame) (getDynamicsInfo[3:5]).
        self._base_offsets = {}
        for t in self.targets:
            if t.link == -1 and t.body not in self._base_offsets:
                pos, orn = self.p.getDynamicsInfo(t.body, -1)[3:5]
                inverse = Rotation.from_quat(orn).inv()
                self._base_offsets[t.body] = (-inverse.apply(pos), inverse)
        links = defaultdict(list)
        self._link_rows = defaultdict(list)
        for i, t in enumerate(self.targets):
            if t.link >= 0:
                links[t.body].append(t.link)
                self._link_rows[t.body].append(i)
        self._links = {body: sorted(set(ids)) for body, ids in links.items()}
        self._base_rows = [i for i, t in enumerate(self.targets) if t.link == -1]
        if self._base_rows:
            self._base_offset_pos = np.array([self._base_offsets[self.targets[i].body][0] for i in self._base_rows])
            self._base_offset_rot = Rotation.concatenate([self._base_offsets[self.targets[i].body][1]
                                                          for i in self._base_rows])
        # Geometry in the link frame, recovered once from the vertices as drawn at set-up.
        self._shared: dict[int, tuple[object, list[int], np.ndarray, np.ndarray | None]] = {}
        self._whole: list[tuple[int, object]] = []
        by_actor = defaultdict(list)
        for i, t in enumerate(self.targets):
            if t.shared:
                by_actor[id(t.actor)].append(i)
            else:
                self._whole.append((i, t.actor))
        for members in by_actor.values():
            actor = self.targets[members[0]].actor
            points = np.asarray(_points(actor), dtype=np.float64)
            local = np.stack([
                Rotation.from_quat(self.targets[i].orientation).inv().apply(
                    points[self.targets[i].start:self.targets[i].stop] - self.targets[i].position)
                for i in members
            ])
            normals = _normals(actor)
            local_normals = None if normals is None else np.stack([
                np.asarray(normals[self.targets[i].start:self.targets[i].stop], dtype=np.float64)
                @ Rotation.from_quat(self.targets[i].orientation).as_matrix()  # row vectors: × R = R⁻¹ applied
                for i in members
            ])
            self._shared[id(actor)] = (actor, members, local, local_normals)

    def _poses(self) -> tuple[np.ndarray, np.ndarray]:
        positions = np.empty((len(self.targets), 3))
        orientations = np.empty((len(self.targets), 4))
        for body, ids in self._links.items():
            states = dict(zip(ids, self.p.getLinkStates(body, ids, computeForwardKinematics=1)))
            for i in self._link_rows[body]:
                positions[i], orientations[i] = states[self.targets[i].link][4:6]
        if self._base_rows:
            com = [self.p.getBasePositionAndOrientation(self.targets[i].body) for i in self._base_rows]
            com_rot = Rotation.from_quat([c[1] for c in com])
            positions[self._base_rows] = np.array([c[0] for c in com]) + com_rot.apply(self._base_offset_pos)
            orientations[self._base_rows] = (com_rot * self._base_offset_rot).as_quat()
        return positions, Rotation.from_quat(orientations).as_matrix()

    def __call__(self) -> None:
        positions, matrices = self._poses()
        for actor, members, local, local_normals in self._shared.values():
            moved = np.einsum("nij,nkj->nki", matrices[members], local) + positions[members][:, None, :]
            points = _points(actor)
            for k, i in enumerate(members):
                points[self.targets[i].start:self.targets[i].stop] = moved[k]
            actor.GetMapper().GetInput().GetPoints().Modified()
            if local_normals is not None:
                turned = np.einsum("nij,nkj->nki", matrices[members], local_normals)
                normals = _normals(actor)
                for k, i in enumerate(members):
                    normals[self.targets[i].start:self.targets[i].stop] = turned[k]
                actor.GetMapper().GetInput().GetPointData().GetNormals().Modified()
        for i, actor in self._whole:
            matrix = np.eye(4)
            matrix[:3, :3], matrix[:3, 3] = matrices[i], positions[i]
            user = vtkMatrix4x4()
            user.DeepCopy(matrix.ravel())
            actor.SetUserMatrix(user)
