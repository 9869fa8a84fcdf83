"""Where pybullet says each drawn thing is, computed by the kit alone.

The expected world vertices of a target are its reference geometry (captured in the link frame
when the actor was built) moved by pybullet's pose of that link frame:

* a base: ``getBasePositionAndOrientation`` gives the centre-of-mass frame (pybullet-facts.md,
  "Frames"); the base link frame is that frame composed with the inverse of the local inertial
  frame from ``getDynamicsInfo(body, -1)[3:5]``;
* a link: ``getLinkState(body, link, computeForwardKinematics=1)[4:6]``, the URDF link frame, with
  forward kinematics recomputed so the pose is not one step stale;
* a soft body has no pose: each vertex belongs at its node, ``getMeshData(body, -1,
  flags=MESH_DATA_SIMULATION_MESH)`` (:func:`nodes`); its item's frame is the identity (:data:`NODES`).

Nothing here reads a sync implementation's state or an actor.

:func:`aabb_half_extents` predicts how loose pybullet's own ``getAABB`` is, so that the bounds check
can hold the drawn box to it tightly.
"""

from __future__ import annotations

from typing import Sequence

import numpy as np
import pybullet
from scipy.spatial.transform import Rotation

from conformance.bullet import poses
from conformance.bullet.client import BoundClient

__all__ = ["NODES", "aabb_half_extents", "expected_vertices", "frames_of", "items_of", "link_frame", "link_frames", "nodes",
           "nodes_of", "read_states", "soft_vertices"]


def link_frame(p: BoundClient, body: int, link: int) -> tuple[np.ndarray, np.ndarray]:
    """World pose (position, x-y-z-w quaternion) of the link frame of ``body``/``link``."""
    if link == -1:
        com_pos, com_orn = p.getBasePositionAndOrientation(body)
        local_pos, local_orn = p.getDynamicsInfo(body, -1)[3:5]
        inv_pos, inv_orn = poses.invert(local_pos, local_orn)
        return poses.compose(com_pos, com_orn, inv_pos, inv_orn)
    state = p.getLinkState(body, link, computeForwardKinematics=1)
    return np.asarray(state[4], dtype=np.float64), np.asarray(state[5], dtype=np.float64)


#: The "link" of a soft body's item: it is drawn at its nodes, in the world, so its frame is the identity
#: (``getDynamicsInfo`` of a soft body reports uninitialised memory where a base's inertial frame would be).
NODES = -2


def items_of(targets) -> list[tuple[int, int]]:
    """The (body, link) item of each target or binding for :func:`link_frames`: a soft body's is (body, NODES)."""
    return [(t.body, NODES if getattr(t, "nodes", None) is not None or getattr(t, "soft", False) else t.link)
            for t in targets]


def link_frames(p: BoundClient, items: Sequence[tuple[int, int]]) -> tuple[np.ndarray, np.ndarray]:
    """Link-frame poses of many (body, link) pairs: positions ``(n, 3)`` and quaternions ``(n, 4)``.

    The same arithmetic as :func:`link_frame`, batched: one ``getLinkStates`` per body with links,
    one scipy call for all bases, and pybullet called directly with the client id (the checks
    call this every frame, so the bound client's per-call wrapping would show)."""
    return frames_of(read_states(p, items))


def read_states(p: BoundClient, items: Sequence[tuple[int, int]]) -> tuple:
    """What :func:`link_frames` reads from pyBullet, as pyBullet returns it: the cheap half, for a
    caller that keeps poses it may never need (:func:`frames_of` makes them link frames)."""
    client = p.client
    links: dict[int, list[int]] = {}
    bases = []
    soft = []
    for i, (body, link) in enumerate(items):
        if link >= 0:
            links.setdefault(body, []).append(i)
        elif link == NODES:
            soft.append(i)
        else:
            bases.append(i)
    states = [(rows, pybullet.getLinkStates(body, [items[i][1] for i in rows], computeForwardKinematics=1,
                                            physicsClientId=client)) for body, rows in links.items()]
    com = [pybullet.getBasePositionAndOrientation(items[i][0], physicsClientId=client) for i in bases]
    inertial = [pybullet.getDynamicsInfo(items[i][0], -1, physicsClientId=client)[3:5] for i in bases]
    nodes_read = [(i, pybullet.getMeshData(items[i][0], -1, flags=pybullet.MESH_DATA_SIMULATION_MESH,
                                           physicsClientId=client)[1]) for i in soft]
    return len(items), states, bases, com, inertial, nodes_read


def frames_of(states: tuple) -> tuple[np.ndarray, np.ndarray]:
    """The link-frame poses (positions ``(n, 3)``, quaternions ``(n, 4)``) of :func:`read_states`' reading."""
    n, links, bases, com, inertial, nodes_read = states
    positions = np.empty((n, 3))
    orientations = np.empty((n, 4))
    soft = [i for i, _ in nodes_read]
    positions[soft], orientations[soft] = 0.0, (0.0, 0.0, 0.0, 1.0)
    for rows, found in links:
        for i, state in zip(rows, found):
            positions[i], orientations[i] = state[4], state[5]
    if bases and all(l[0] == (0.0, 0.0, 0.0) and l[1] == (0.0, 0.0, 0.0, 1.0) for l in inertial):
        # Every base's centre of mass is its link frame (the usual case): the pose as pyBullet gives it,
        # without the five scipy calls a frame that made most of a 10,000-frame check's reading.
        positions[bases] = [c[0] for c in com]
        orientations[bases] = [c[1] for c in com]
    elif bases:
        com_rot = Rotation.from_quat([c[1] for c in com])
        frame_rot = com_rot * Rotation.from_quat([l[1] for l in inertial]).inv()
        positions[bases] = np.array([c[0] for c in com]) - frame_rot.apply(np.array([l[0] for l in inertial]))
        orientations[bases] = frame_rot.as_quat()
    return positions, orientations


def nodes(p: BoundClient, body: int) -> np.ndarray:
    """The world positions ``(n, 3)`` of soft body ``body``'s simulated nodes now (``getMeshData(body, -1,
    flags=MESH_DATA_SIMULATION_MESH)``; without the flag pyBullet gives the visual mesh, which may differ)."""
    found = pybullet.getMeshData(body, -1, flags=pybullet.MESH_DATA_SIMULATION_MESH, physicsClientId=p.client)[1]
    return np.asarray(found, dtype=np.float64).reshape(-1, 3)


def soft_vertices(p: BoundClient, targets) -> dict[int, np.ndarray]:
    """Where each soft target's vertices belong now, by target index: its nodes (``Target.nodes``) as
    :func:`nodes` reads them, one read per body."""
    read: dict[int, np.ndarray] = {}
    found = {}
    for i, t in enumerate(targets):
        if t.nodes is not None:
            if t.body not in read:
                read[t.body] = nodes(p, t.body)
            found[i] = read[t.body][t.nodes]
    return found


def nodes_of(states: tuple) -> dict[int, np.ndarray]:
    """The node positions ``(n, 3)`` of each soft item (by item index) in :func:`read_states`' reading."""
    return {i: np.asarray(found, dtype=np.float64).reshape(-1, 3) for i, found in states[5]}


def expected_vertices(local: np.ndarray, position, orientation) -> np.ndarray:
    """Reference geometry ``local`` (n, 3, link frame) placed at the given link-frame pose."""
    return poses.apply(position, orientation, local)


def aabb_half_extents(p: BoundClient, body: int, link: int) -> np.ndarray:
    """The half extents of the box ``getAABB(body, link)`` reports for a box, sphere or cylinder,
    derived the way Bullet builds it (bullet3 ``btTransformAabb``, ``btCompoundShape::getAabb``):

    * a box or cylinder is bounded by its own box (half extents ``h``, ``(r, r, h/2)``) turned with
      the shape, ``|R|·h``: exact for a box, the box of a turned box for a cylinder; a sphere, exactly;
    * a shape off its body's centre of mass (inertial offset, or a collision frame of its own) is the
      child of a compound: the child's box, turned with the child frame, is turned again with the
      centre-of-mass frame, ``|R_com|·|R_child|·h``, and a sphere's box becomes that of a turned cube.
    """
    shape = p.getCollisionShapeData(body, link)[0]
    kind, dims, child_pos, child_orn = shape[2], shape[3], shape[5], shape[6]
    if kind == pybullet.GEOM_BOX:
        half = np.asarray(dims, dtype=np.float64) / 2
    elif kind == pybullet.GEOM_CYLINDER:
        half = np.array([dims[1], dims[1], dims[0] / 2])
    elif kind == pybullet.GEOM_SPHERE:
        half = np.full(3, float(dims[0]))
    else:
        raise ValueError(f"body {body} link {link}: shape type {kind} is not a box, sphere or cylinder")
    com_orn = p.getBasePositionAndOrientation(body)[1] if link == -1 else p.getLinkState(body, link)[1]
    turned = np.abs(Rotation.from_quat(com_orn).as_matrix())
    compound = np.any(np.abs(child_pos) > 0) or not np.isclose(abs(child_orn[3]), 1.0)
    if not compound:
        return half if kind == pybullet.GEOM_SPHERE else turned @ half
    if kind != pybullet.GEOM_SPHERE:
        half = np.abs(Rotation.from_quat(child_orn).as_matrix()) @ half
    return turned @ half
