"""The renderer-free steps of the test suite's right and wrong syncs, written once for both backends.

Nothing here imports FURY, VTK or pygfx. A step reaches an actor's arrays only through
:class:`ActorArrays` (``vertex_view``, ``normal_view``, ``announce``), which ``right_syncs_vtk`` (FURY
0.12) and ``right_syncs_pygfx`` (FURY 2) fill in; whatever else touches an actor (placing a whole
one, announcing a changed range) is in those files and in ``wrong_syncs_<backend>``.

* pose helpers: :func:`link_frame` (scipy), :func:`link_frame_offsets` (each base's inverse inertial
  frame, scipy) and :func:`inverse_inertial_frames` (the same with pybullet's ``invertTransform``),
  :func:`link_frame_geometry` (a shared target's vertex range in its link frame), :func:`pose_matrix`,
  :func:`euler_angles`; all for rigid targets only: a soft body's target (``Target.nodes`` not None)
  has no pose (``getDynamicsInfo`` of a soft body reports garbage), each sync copies its nodes
  (:func:`soft_nodes`, pyBullet's simulated mesh) into its vertices in its own way;
* the right syncs' steps, under each backend's class of the same name without ``Steps``:
  :class:`PerTargetSteps`, :class:`UserMatrixSteps`, :class:`IncrementalSteps`,
  :class:`PositionOrientationSteps`, and :func:`vectorised_vertex_sync`, the closure itself;
* the renderer-free halves of the wrong syncs that also touch the renderer, mixins to put before a
  backend's ``PerTargetSync``: :class:`InflatedGeometry` (``InflatedAgainstZFighting``),
  :class:`ExampleVertexRanges` (``WrongVertexRange``), :class:`StaleCentre` (``CentreNotUpdated``),
  :class:`Float32Steps` (``Float32Incremental``), :class:`NormalsLeftAsBuilt` (``NormalsNotRotated``).

The wrong syncs that never touch the renderer are in ``wrong_syncs`` itself.
"""

from __future__ import annotations

import warnings
from collections import defaultdict

import numpy as np
from scipy.spatial.transform import Rotation

__all__ = [
    "ActorArrays",
    "ExampleVertexRanges",
    "Float32Steps",
    "IncrementalSteps",
    "InflatedGeometry",
    "NormalsLeftAsBuilt",
    "PerTargetSteps",
    "PositionOrientationSteps",
    "StaleCentre",
    "UserMatrixSteps",
    "euler_angles",
    "inverse_inertial_frames",
    "link_frame",
    "link_frame_geometry",
    "link_frame_offsets",
    "pose_matrix",
    "soft_nodes",
    "vectorised_vertex_sync",
]


# ---- poses ---------------------------------------------------------------------------------------------

def _bases(targets) -> list[int]:
    """The rigid bodies whose base is a target, in the order they first appear (a soft body has no
    inertial frame to undo: ``getDynamicsInfo`` reports garbage for it)."""
    return list(dict.fromkeys(t.body for t in targets if t.link == -1 and t.nodes is None))


def soft_nodes(p, body: int):
    """A soft body's simulated nodes now, in world coordinates, as pyBullet returns them (a tuple of
    (x, y, z)); without the flag ``getMeshData`` gives the visual mesh, which need not be the nodes."""
    return p.getMeshData(body, -1, flags=p.MESH_DATA_SIMULATION_MESH)[1]


def link_frame(p, body: int, link: int):
    """Link-frame world pose as (position, scipy Rotation), of a rigid body's base or link."""
    if link >= 0:
        state = p.getLinkState(body, link, computeForwardKinematics=1)
        return np.asarray(state[4], dtype=np.float64), Rotation.from_quat(state[5])
    com_pos, com_orn = p.getBasePositionAndOrientation(body)
    inertial_pos, inertial_orn = p.getDynamicsInfo(body, -1)[3:5]
    com = Rotation.from_quat(com_orn)
    to_link = Rotation.from_quat(inertial_orn).inv()
    return com.apply(-to_link.apply(inertial_pos)) + np.asarray(com_pos), com * to_link


def link_frame_offsets(p, targets) -> dict:
    """Each base's link frame in its centre-of-mass frame (getBasePositionAndOrientation's), by body:
    ``(offset, Rotation)``, the inverse of its local inertial frame ``getDynamicsInfo(body, -1)[3:5]``."""
    offsets = {}
    for body in _bases(targets):
        pos, orn = p.getDynamicsInfo(body, -1)[3:5]
        back = Rotation.from_quat(orn).inv()
        offsets[body] = (-back.apply(pos), back)
    return offsets


def inverse_inertial_frames(p, targets) -> dict:
    """The same inverse by pybullet's own ``invertTransform``, by body: ``(position, quaternion)``."""
    return {body: p.invertTransform(*p.getDynamicsInfo(body, -1)[3:5]) for body in _bases(targets)}


def link_frame_geometry(t, vertices, normals):
    """A shared target's vertex range, and its normals (None where ``normals``, the actor's, is None),
    in its link frame in float64, from the actor's arrays as built at ``t.position``/``t.orientation``."""
    back = Rotation.from_quat(t.orientation).inv()
    local = back.apply(np.array(vertices[t.start:t.stop], dtype=np.float64) - t.position)
    if normals is None:
        return local, None
    return local, back.apply(np.asarray(normals[t.start:t.stop], dtype=np.float64))


def pose_matrix(rotation: np.ndarray, position) -> np.ndarray:
    """The 4x4 float64 matrix of a 3x3 rotation and a translation."""
    matrix = np.eye(4)
    matrix[:3, :3] = rotation
    matrix[:3, 3] = position
    return matrix


def euler_angles(rotation: Rotation, seq: str, degrees: bool = False) -> np.ndarray:
    """``rotation.as_euler(seq, degrees)`` without scipy's gimbal-lock warning."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # "Gimbal lock detected": the rotation is still exact
        return rotation.as_euler(seq, degrees=degrees)


# ---- what a backend fills in ---------------------------------------------------------------------------

class ActorArrays:
    """Where a backend keeps an actor's arrays and how it is told they changed: the one part of the
    steps below that touches an actor (each backend's ``_Arrays`` in ``right_syncs_<backend>``)."""

    @staticmethod
    def vertex_view(actor) -> np.ndarray:
        """The actor's vertices as a writable (n, 3) view."""
        raise NotImplementedError

    @staticmethod
    def normal_view(actor) -> np.ndarray | None:
        """The actor's stored vertex normals as a writable view, or None (the renderer derives them)."""
        raise NotImplementedError

    @staticmethod
    def announce(actor) -> None:
        """Tell the renderer that the actor's vertices (and normals, where it has them) changed."""
        raise NotImplementedError


# ---- the right syncs' steps ----------------------------------------------------------------------------

class PerTargetSteps(ActorArrays):
    """``PerTargetSync`` but for placing a whole actor (``place_whole``) and announcing the shared
    actors written (``finish``): each method is a step that ``wrong_syncs`` gets wrong in one way."""

    def __init__(self, world):
        self.world = world
        self.p = world.p
        self.targets = list(world.targets)
        # Inverse of each base's local inertial frame: getBasePositionAndOrientation is the COM frame.
        self.to_link = link_frame_offsets(self.p, self.targets)
        # Bases whose centre of mass is their link frame: their pose as pybullet gives it, no composing
        self.at_com = {body for body, (offset, back) in self.to_link.items() if not offset.any() and not back.magnitude()}
        # Shared actors: the geometry of each vertex range in its link frame, captured once.
        self.local, self.local_normals = {}, {}
        for t in self.targets:
            if t.shared:
                local, normals = link_frame_geometry(t, self.vertex_view(t.actor), self.normal_view(t.actor))
                self.local[t.name] = local
                if normals is not None:
                    self.local_normals[t.name] = normals

    # -- the steps a mistake can hide in ---------------------------------------------------------
    def link_pose(self, t):
        """World pose (position, x-y-z-w quaternion) of the target's link frame; a soft body's is the
        world's (its nodes are world coordinates, its actor keeps the identity)."""
        if t.nodes is not None:
            return (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)
        if t.link >= 0:
            return self.p.getLinkState(t.body, t.link, computeForwardKinematics=1)[4:6]
        com_pos, com_orn = self.p.getBasePositionAndOrientation(t.body)
        if t.body in self.at_com:
            return com_pos, com_orn
        offset, back = self.to_link[t.body]
        com = Rotation.from_quat(com_orn)
        return com.apply(offset) + com_pos, (com * back).as_quat()

    def matrix(self, orn) -> np.ndarray:
        """3×3 rotation matrix of a pybullet quaternion: pybullet's own nine numbers, row by row (a scipy
        ``Rotation`` a target a frame made most of a brick wall's sync, 40 µs each)."""
        return np.reshape(self.p.getMatrixFromQuaternion(orn), (3, 3))

    def to_sync(self):
        return self.targets

    def place_whole(self, t, pos, orn) -> None:
        """Give a whole actor the pose (the backend's)."""
        raise NotImplementedError

    def place_shared(self, t, pos, orn) -> None:
        rotation = self.matrix(orn)
        self.vertex_view(t.actor)[t.start:t.stop] = self.local[t.name] @ rotation.T + pos
        if t.name in self.local_normals:
            self.normal_view(t.actor)[t.start:t.stop] = self.local_normals[t.name] @ rotation.T

    def place_soft(self, t) -> None:
        """Copy a soft target's nodes, read for it alone, into its vertices (they have no pose to place)."""
        self.vertex_view(t.actor)[t.start:t.stop] = np.asarray(soft_nodes(self.p, t.body))[t.nodes]

    def finish(self, actors) -> None:
        """Announce the vertices (and normals) written into these shared and soft actors (the backend's)."""
        raise NotImplementedError

    def draw(self, posed) -> None:
        """Place each ``(target, position, orientation)`` and finish the shared and soft actors written."""
        touched = {}
        for t, pos, orn in posed:
            if t.nodes is not None:
                self.place_soft(t)
                touched[id(t.actor)] = t.actor
            elif t.shared:
                self.place_shared(t, pos, orn)
                touched[id(t.actor)] = t.actor
            else:
                self.place_whole(t, pos, orn)
        self.finish(touched.values())

    def __call__(self):
        self.draw((t, *self.link_pose(t)) for t in self.to_sync())


class UserMatrixSteps(ActorArrays):
    """``UserMatrixSync`` but for its loop: pybullet's own transforms for the pose, the rewrite of a
    shared target's range; the backend sets whole actors' matrices and announces the ranges."""

    def __init__(self, world):
        self.p = world.p
        self.targets = world.targets
        self.inertial = inverse_inertial_frames(self.p, self.targets)  # body -> inverse of its base's local inertial frame
        self.geometry = {  # target name -> (link-frame vertices, link-frame normals or None)
            t.name: link_frame_geometry(t, self.vertex_view(t.actor), self.normal_view(t.actor))
            for t in self.targets if t.shared}

    def copy_nodes(self, t, read: dict) -> None:
        """Write a soft target's nodes into its vertices, each body's nodes read once a frame into ``read``
        (body -> float64 array) however many targets follow them."""
        if t.body not in read:
            read[t.body] = np.array(soft_nodes(self.p, t.body), dtype=np.float64)
        self.vertex_view(t.actor)[t.start:t.stop] = np.take(read[t.body], t.nodes, axis=0)

    def pose(self, t):
        if t.link >= 0:
            return self.p.getLinkState(t.body, t.link, computeForwardKinematics=1)[4:6]
        com_pos, com_orn = self.p.getBasePositionAndOrientation(t.body)
        inv_pos, inv_orn = self.inertial[t.body]
        if inv_pos == (0.0, 0.0, 0.0) and inv_orn == (0.0, 0.0, 0.0, 1.0):
            return com_pos, com_orn  # skip multiplyTransforms' float32 rounding when there is no offset
        return self.p.multiplyTransforms(com_pos, com_orn, inv_pos, inv_orn)

    def move_range(self, t, pos, orn) -> None:
        """Rewrite a shared target's vertex range (and normals) at pose ``pos``, ``orn``."""
        rotation = Rotation.from_quat(orn)
        vertices, normals = self.geometry[t.name]
        self.vertex_view(t.actor)[t.start:t.stop] = rotation.apply(vertices) + pos
        if normals is not None:
            self.normal_view(t.actor)[t.start:t.stop] = rotation.apply(normals)

    @staticmethod
    def whole_matrix(pos, orn) -> np.ndarray:
        """A whole actor's 4x4 matrix at pose ``pos``, ``orn``."""
        return pose_matrix(Rotation.from_quat(orn).as_matrix(), pos)


class IncrementalSteps(ActorArrays):
    """``IncrementalSync`` but for its loop: the float64 copies and the turn since the last frame of a
    shared range or of a whole actor's matrix; the backend sets the matrices and announces the ranges."""

    def __init__(self, world):
        self.p = world.p
        self.targets = world.targets
        self.last = {}  # target name -> (position, Rotation) it is drawn at now
        self.vertices = {}  # actor id -> float64 copy of its vertices (shared actors)
        self.normals = {}
        self.matrices = {}  # target name -> 4x4 float64 matrix of a whole actor
        for t in self.targets:
            if t.nodes is not None:
                continue  # a soft body: nothing to turn (refresh_nodes)
            self.last[t.name] = (np.array(t.position, dtype=np.float64), Rotation.from_quat(t.orientation))
            if t.shared and id(t.actor) not in self.vertices:
                self.vertices[id(t.actor)] = np.array(self.vertex_view(t.actor), dtype=np.float64)
                normals = self.normal_view(t.actor)
                self.normals[id(t.actor)] = None if normals is None else np.array(normals, dtype=np.float64)
            if not t.shared:
                self.matrices[t.name] = np.eye(4)

    def motion(self, t):
        """``(position now, position last drawn, rotation matrix since then)`` of the target's link
        frame; from now on it is drawn at the pose now."""
        pos, rot = link_frame(self.p, t.body, t.link)
        old_pos, old_rot = self.last[t.name]
        self.last[t.name] = (pos, rot)
        return pos, old_pos, (rot * old_rot.inv()).as_matrix()

    def turn_range(self, t) -> None:
        """Turn and move a shared target's range (and normals) by its motion, in the float64 copy and the actor."""
        pos, old_pos, delta = self.motion(t)
        vertices = self.vertices[id(t.actor)]
        vertices[t.start:t.stop] = (vertices[t.start:t.stop] - old_pos) @ delta.T + pos
        self.vertex_view(t.actor)[t.start:t.stop] = vertices[t.start:t.stop]
        normals = self.normals[id(t.actor)]
        if normals is not None:
            normals[t.start:t.stop] = normals[t.start:t.stop] @ delta.T
            self.normal_view(t.actor)[t.start:t.stop] = normals[t.start:t.stop]

    def refresh_nodes(self, t) -> None:
        """A soft target's vertices, copied fresh from its nodes: a soft body does not move by one turn
        and shift, so there is no motion since the last frame to apply, and nothing to pile up."""
        self.vertex_view(t.actor)[t.start:t.stop] = np.asarray(soft_nodes(self.p, t.body), dtype=np.float64)[t.nodes]

    def turn_whole(self, t) -> np.ndarray:
        """A whole actor's 4x4 float64 matrix turned and moved by its motion."""
        pos, old_pos, delta = self.motion(t)
        step = np.eye(4)
        step[:3, :3] = delta
        step[:3, 3] = pos - delta @ old_pos
        matrix = self.matrices[t.name] = step @ self.matrices[t.name]
        return matrix


class PositionOrientationSteps(ActorArrays):
    """``PositionOrientationSync`` but for placing a whole actor by position and Euler angles
    (``place_whole``, the backend's): pybullet's matrices for shared actors, row by row."""

    def __init__(self, world):
        self.p = world.p
        self.whole = [t for t in world.targets if not t.shared and t.nodes is None]
        self.shared = [t for t in world.targets if t.shared]
        self.soft = [t for t in world.targets if t.nodes is not None]
        self.local = {}
        for t in self.shared:
            back = np.reshape(self.p.getMatrixFromQuaternion(list(t.orientation)), (3, 3)).T
            rows = np.array(self.vertex_view(t.actor)[t.start:t.stop], dtype=np.float64)
            normals = self.normal_view(t.actor)
            self.local[t.name] = (
                [back @ (row - t.position) for row in rows],
                None if normals is None else [back @ np.asarray(n, dtype=np.float64) for n in normals[t.start:t.stop]],
            )

    def place_whole(self, t, pos, rot) -> None:
        """Give a whole actor the position and scipy Rotation by the renderer's Euler angles (the backend's)."""
        raise NotImplementedError

    def __call__(self):
        for t in self.whole:
            self.place_whole(t, *link_frame(self.p, t.body, t.link))
        touched = {}
        for t in self.shared:
            pos, rot = link_frame(self.p, t.body, t.link)
            matrix = np.reshape(self.p.getMatrixFromQuaternion(rot.as_quat().tolist()), (3, 3))
            vertices = self.vertex_view(t.actor)
            rows, normals = self.local[t.name]
            for k, row in enumerate(rows):
                vertices[t.start + k] = matrix @ row + pos
            if normals is not None:
                stored = self.normal_view(t.actor)
                for k, normal in enumerate(normals):
                    stored[t.start + k] = matrix @ normal
            touched[id(t.actor)] = t.actor
        for t in self.soft:  # no pose: each vertex is its node, copied row by row
            nodes = soft_nodes(self.p, t.body)
            vertices = self.vertex_view(t.actor)
            for k, node in enumerate(t.nodes):
                vertices[t.start + k] = nodes[node]
            touched[id(t.actor)] = t.actor
        for actor in touched.values():
            self.announce(actor)


def vectorised_vertex_sync(world, arrays: type[ActorArrays]):
    """``right_syncs``' closure that rewrites every actor's vertices (whole actors too) with one einsum
    per actor, reaching them through the backend's ``arrays``; a soft body's actor with one gather of
    its nodes, read once a frame per body."""
    p = world.p
    groups = defaultdict(list)
    soft = defaultdict(list)  # soft body -> (actor, vertex range, nodes) of each target following its nodes
    for i, t in enumerate(world.targets):
        if t.nodes is None:
            groups[id(t.actor)].append(i)
        else:
            soft[t.body].append((t.actor, slice(t.start, t.stop), t.nodes))
    plan = []
    for members in groups.values():
        actor = world.targets[members[0]].actor
        points = np.asarray(arrays.vertex_view(actor), dtype=np.float64)
        normals = arrays.normal_view(actor)
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
    rigid = [i for i, t in enumerate(world.targets) if t.nodes is None]

    def sync():
        positions, matrices = np.zeros((len(bodies), 3)), np.zeros((len(bodies), 3, 3))  # soft targets' rows unused
        if rigid:
            frames = [link_frame(p, *bodies[i]) for i in rigid]
            positions[rigid] = [f[0] for f in frames]
            matrices[rigid] = Rotation.concatenate([f[1] for f in frames]).as_matrix()
        for body, copies in soft.items():
            nodes = np.asarray(soft_nodes(p, body), dtype=np.float64)
            for actor, rows, follows in copies:
                arrays.vertex_view(actor)[rows] = nodes[follows]  # one gather a target
                arrays.announce(actor)
        for actor, members, ranges, local, local_normals in plan:
            moved = np.einsum("nij,nkj->nki", matrices[members], local) + positions[members][:, None, :]
            vertices = arrays.vertex_view(actor)
            for k, (a, b) in enumerate(ranges):
                vertices[a:b] = moved[k]
            if local_normals is not None:
                turned = np.einsum("nij,nkj->nki", matrices[members], local_normals)
                normals = arrays.normal_view(actor)
                for k, (a, b) in enumerate(ranges):
                    normals[a:b] = turned[k]
            arrays.announce(actor)

    return sync


# ---- the renderer-free halves of renderer-specific wrong syncs ----------------------------------------
# Each is a mixin to list before a backend's PerTargetSync, whose link_pose, local geometry,
# vertex_view, normal_view, place_whole and finish it uses.

class InflatedGeometry:
    """``InflatedAgainstZFighting``'s shared actors: link-frame geometry ``SCALE`` times too large (the
    backend scales whole actors)."""

    SCALE = 1.001

    def __init__(self, world):
        super().__init__(world)
        for name in self.local:
            self.local[name] = self.local[name] * self.SCALE


class ExampleVertexRanges:
    """``WrongVertexRange``'s shared actors: the wrecking-ball example's incremental vertex recipe, with
    the vertices per object (``sec``) of every shared actor computed from the object count of the
    first shared actor."""

    def __init__(self, world):
        super().__init__(world)
        by_actor = defaultdict(list)
        for t in self.targets:
            if t.shared:
                by_actor[id(t.actor)].append(t)
        self.slots = {}  # target name -> (its index in its actor, sec, that actor's centres, orientations)
        num_objects = None
        for members in by_actor.values():
            vertices = self.vertex_view(members[0].actor)
            if num_objects is None:
                num_objects = len(members)  # the example's brick_centers.shape[0], reused for the chain
            sec = int(vertices.shape[0] / num_objects)
            centers = np.array([t.position for t in members])
            orns = np.array([t.orientation for t in members])
            for index, t in enumerate(members):
                self.slots[t.name] = (index, sec, centers, orns)

    def place_shared(self, t, pos, orn):
        p = self.p
        index, sec, centers, orns = self.slots[t.name]
        vertices = self.vertex_view(t.actor)
        rot_mat = np.reshape(p.getMatrixFromQuaternion(p.getDifferenceQuaternion(orn, orns[index])), (3, 3))
        vertices[index * sec: index * sec + sec] = \
            (vertices[index * sec: index * sec + sec] - centers[index]) @ rot_mat + pos
        normals = self.normal_view(t.actor)
        if normals is not None:  # turned with the same range and rotation: the ranges are the only mistake
            normals[index * sec: index * sec + sec] = normals[index * sec: index * sec + sec] @ rot_mat
        centers[index] = pos
        orns[index] = orn


class StaleCentre:
    """``CentreNotUpdated``'s shared actors: the guide's incremental single-actor recipe, turning each
    range about its tracked centre, which it never updates."""

    def __init__(self, world):
        super().__init__(world)
        shared = [t for t in self.targets if t.shared]
        self.centers = {t.name: np.array(t.position, dtype=np.float64) for t in shared}
        self.orns = {t.name: np.array(t.orientation, dtype=np.float64) for t in shared}

    def place_shared(self, t, pos, orn):
        vertices = self.vertex_view(t.actor)
        delta = np.reshape(self.p.getMatrixFromQuaternion(self.p.getDifferenceQuaternion(orn, self.orns[t.name])), (3, 3))
        vertices[t.start:t.stop] = (vertices[t.start:t.stop] - self.centers[t.name]) @ delta + pos
        normals = self.normal_view(t.actor)
        if normals is not None:  # turned right: the stale centre is the only mistake
            normals[t.start:t.stop] = normals[t.start:t.stop] @ delta
        self.orns[t.name] = orn  # ... and no self.centers[t.name] = pos


class Float32Steps:
    """``Float32Incremental``: the incremental recipe on every actor's vertices and normals, kept in
    float32, each actor written whole and finished after every frame."""

    def __init__(self, world):
        super().__init__(world)
        self.vertices, self.normals = {}, {}
        for t in self.targets:
            if id(t.actor) not in self.vertices:
                self.vertices[id(t.actor)] = np.array(self.vertex_view(t.actor), dtype=np.float32)
                normals = self.normal_view(t.actor)
                if normals is not None:
                    self.normals[id(t.actor)] = normals  # float32 already, the actor's own array
        self.last = {t.name: (np.array(t.position, np.float32), np.array(t.orientation, np.float32)) for t in self.targets}

    def __call__(self):
        actors = {}
        for t in self.targets:
            if t.nodes is not None:  # a soft body's vertices are its nodes, copied (in float32 too): no pose to step
                self.vertices[id(t.actor)][t.start:t.stop] = np.asarray(soft_nodes(self.p, t.body))[t.nodes]
                actors[id(t.actor)] = t.actor
                continue
            pos, orn = self.link_pose(t)
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
            self.vertex_view(actor)[:] = self.vertices[key]
            self.finish([actor])


class NormalsLeftAsBuilt:
    """``NormalsNotRotated``'s shared actors: vertices rewritten, stored normals left as built."""

    def place_shared(self, t, pos, orn):
        self.vertex_view(t.actor)[t.start:t.stop] = self.local[t.name] @ self.matrix(orn).T + pos
