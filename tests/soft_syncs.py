"""Deliberately wrong ways of drawing a soft body: the kit's reference sync with its soft-body part
(:class:`conformance.implementations.frames.SoftBodies`) rewritten the way a user gets it wrong. Rigid
bodies stay right, so the mistake is the only difference.

They live apart from ``wrong_syncs`` because only the soft scenes (``cloth``, ``soft_ball``, ``jelly``) can reject
them (``EveryNode`` only the volumetric ``jelly``); ``tests/test_soft_bodies.py`` runs them there.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

import pybullet

from conformance.bullet import truth
from conformance.implementations.frames import SoftBodies
from conformance.implementations.reference import ReferenceSync

__all__ = ["CopiedOnce", "EveryNode", "Float16Nodes", "LoadFrameNodes", "MovesTheCloth", "NodesReversed", "OneStepLateNodes",
           "PartlyCopied", "PosedAsWell", "StillsTheNodes", "VisualMesh"]


class _LateNodes(SoftBodies):
    def vertices(self, t, nodes):
        kept = getattr(self, "kept", {})
        self.kept = {**kept, t.name: nodes[t.nodes]}
        return kept.get(t.name, nodes[t.nodes])


class OneStepLateNodes(ReferenceSync):
    """Wrong: keeps each frame's nodes to draw at the next ("read now, draw next frame"), so the cloth is one
    step behind pyBullet — what a timer callback draws when it copies before stepSimulation.

    Diagnosis: previous-step
    """

    soft_bodies = _LateNodes


class _Reversed(SoftBodies):
    def vertices(self, t, nodes):
        return nodes[t.nodes][::-1]


class NodesReversed(ReferenceSync):
    """Wrong: copies the nodes in another order than the faces expect (reversed), so every triangle joins
    the wrong nodes though the cloth's outline looks nearly right.

    Diagnosis: node-order
    """

    soft_bodies = _Reversed


class _Once(SoftBodies):
    def vertices(self, t, nodes):
        if not hasattr(self, "first"):
            self.first = {}
        return self.first.setdefault(t.name, nodes[t.nodes])


class CopiedOnce(ReferenceSync):
    """Wrong: copies the nodes at the first call only ("the mesh is set up once"), so the soft body stays
    drawn as it was built while pyBullet's sags and bounces.

    Diagnosis: never-moved
    """

    soft_bodies = _Once




class _Half(SoftBodies):
    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.kept = {}

    def vertices(self, t, nodes):
        # The first half of the nodes copied each call; the rest kept as first copied (the loop's bound is
        # another mesh's count)
        first = self.kept.setdefault(t.name, nodes[t.nodes].copy())
        half = len(t.nodes) // 2
        return np.concatenate([nodes[t.nodes][:half], first[half:]])


class PartlyCopied(ReferenceSync):
    """Wrong: copies only the first half of the nodes at every call ("the loop bound came from the other mesh"),
    so half the soft body follows pyBullet and the other half stays as built.

    Diagnosis: part-copied
    """

    soft_bodies = _Half


class _Float16(SoftBodies):
    def vertices(self, t, nodes):
        return nodes[t.nodes].astype(np.float16)


class Float16Nodes(ReferenceSync):
    """Wrong: keeps the soft body's vertices in float16 ("half the memory for a big cloth"), so every node is
    drawn rounded to 11 bits, up to a millimetre off at two metres.

    Diagnosis: float16
    """

    soft_bodies = _Float16


class _PosedAsWell(SoftBodies):
    def vertices(self, t, nodes):
        pos, orn = pybullet.getBasePositionAndOrientation(t.body, physicsClientId=self.client)
        return nodes[t.nodes] @ Rotation.from_quat(orn).as_matrix().T + pos


class PosedAsWell(ReferenceSync):
    """Wrong: copies the nodes, and moves them by the soft body's getBasePositionAndOrientation as well, as the
    program's rigid bodies are posed (one recipe for every body: what an actor given the body's pose draws).
    The nodes are already in the world's frame, so the cloth is drawn moved and turned a second time.

    Diagnosis: soft-posed
    """

    soft_bodies = _PosedAsWell


class _Visual(SoftBodies):
    def vertices(self, t, nodes):
        # getMeshData without MESH_DATA_SIMULATION_MESH: the visual mesh, one vertex per corner of each face
        visual = pybullet.getMeshData(t.body, -1, physicsClientId=self.client)[1]
        return np.asarray(visual, dtype=np.float64)[t.nodes]


class VisualMesh(ReferenceSync):
    """Wrong: reads the soft body with ``getMeshData(body)`` (no ``MESH_DATA_SIMULATION_MESH`` flag), pyBullet's
    visual mesh, and copies its first vertices: they are the corners of the first faces, not the nodes in order.

    Diagnosis: visual-mesh
    """

    soft_bodies = _Visual


class MovesTheCloth(ReferenceSync):
    """Wrong: draws right, then writes the soft bodies' nodes back into pyBullet (``resetMeshData``), 1 µm
    higher, to "keep the drawing and the physics together": a sync must only read.

    Diagnosis: -
    """

    def __call__(self):
        super().__call__()
        for t in self.targets:
            if t.nodes is not None:
                self.p.resetMeshData(t.body, vertices=(truth.nodes(self.p, t.body) + [0.0, 0.0, 1e-6]).tolist())


class _EveryNode(SoftBodies):
    def vertices(self, t, nodes):
        return nodes[:len(t.nodes)]  # vertex k at node k: right for a surface, whose every node is drawn


class EveryNode(ReferenceSync):
    """Wrong: draws vertex k at node k, as a sync written for surface soft bodies does, where every node is drawn
    in order. A volumetric body draws only its boundary nodes (``Target.nodes``), so its vertices land on the
    first nodes, inside and out: right on ``cloth`` and ``soft_ball``, wrong on ``jelly``.

    Diagnosis: every-node
    """

    soft_bodies = _EveryNode


class _LoadFrame(SoftBodies):
    def vertices(self, t, nodes):
        # the nodes kept in the body's frame as first read, then posed by the body's pose now, as a rigid
        # body's vertices are: right while nothing turns the soft body's frame
        centre, orientation = pybullet.getBasePositionAndOrientation(t.body, physicsClientId=self.client)
        now = Rotation.from_quat(orientation)
        first = getattr(self, "first", {})
        self.first = {**first, t.body: first.get(t.body, now)}
        local = self.first[t.body].inv().apply(nodes[t.nodes] - centre)
        return now.apply(local) + centre


class LoadFrameNodes(ReferenceSync):
    """Wrong: keeps each soft body's nodes in the body's frame as it was loaded and poses them by the body's
    pose now (``getBasePositionAndOrientation``), as it would a rigid body's vertices: exact while the body's
    frame does not turn. pyBullet turns it itself once the cloth catches the box (frame 96) and once the jelly
    lands (frame 48); the soft ball's never turns in its own story, so there only the kit's events reveal it:
    a teleport turns every node (``resetBasePositionAndOrientation``), and the ball is drawn turned twice.

    Diagnosis: -
    """

    soft_bodies = _LoadFrame


class StillsTheNodes(ReferenceSync):
    """Wrong: draws right, then sets every soft body's node velocities to zero (``resetBaseVelocity``) "so the cloth
    does not jitter in the picture": the nodes stay where they are, so nothing a sync could read back changed,
    but the next step starts from rest. A sync must only read.

    Diagnosis: -
    """

    def __call__(self):
        super().__call__()
        for t in self.targets:
            if t.nodes is not None:
                self.p.resetBaseVelocity(t.body, [0.0, 0.0, 0.0], [0.0, 0.0, 0.0])
