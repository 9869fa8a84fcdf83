"""Deliberately wrong ways of drawing a soft body: the kit's reference sync with its soft-body part
(:class:`conformance.implementations.frames.SoftBodies`) rewritten the way a user gets it wrong. Rigid
bodies stay right, so the mistake is the only difference.

They live apart from ``wrong_syncs`` because only the soft scenes (``cloth``, ``soft_ball``) can reject
them; ``tests/test_soft_bodies.py`` runs them there.
"""

from __future__ import annotations

from conformance.bullet import truth
from conformance.implementations.frames import SoftBodies
from conformance.implementations.reference import ReferenceSync

__all__ = ["CopiedOnce", "MovesTheCloth", "NodesReversed", "OneStepLateNodes"]


class _LateNodes(SoftBodies):
    def vertices(self, t, nodes):
        kept = getattr(self, "kept", {})
        self.kept = {**kept, t.name: nodes[t.nodes]}
        return kept.get(t.name, nodes[t.nodes])


class OneStepLateNodes(ReferenceSync):
    """Wrong: keeps each frame's nodes to draw at the next ("read now, draw next frame"), so the cloth is one
    step behind pyBullet — what a timer callback draws when it copies before stepSimulation."""

    soft_bodies = _LateNodes


class _Reversed(SoftBodies):
    def vertices(self, t, nodes):
        return nodes[t.nodes][::-1]


class NodesReversed(ReferenceSync):
    """Wrong: copies the nodes in another order than the faces expect (reversed), so every triangle joins
    the wrong nodes though the cloth's outline looks nearly right."""

    soft_bodies = _Reversed


class _Once(SoftBodies):
    def vertices(self, t, nodes):
        if not hasattr(self, "first"):
            self.first = {}
        return self.first.setdefault(t.name, nodes[t.nodes])


class CopiedOnce(ReferenceSync):
    """Wrong: copies the nodes at the first call only ("the mesh is set up once"), so the soft body stays
    drawn as it was built while pyBullet's sags and bounces."""

    soft_bodies = _Once




class MovesTheCloth(ReferenceSync):
    """Wrong: draws right, then writes the soft bodies' nodes back into pyBullet (``resetMeshData``), 1 µm
    higher, to "keep the drawing and the physics together": a sync must only read."""

    def __call__(self):
        super().__call__()
        for t in self.targets:
            if t.nodes is not None:
                self.p.resetMeshData(t.body, vertices=(truth.nodes(self.p, t.body) + [0.0, 0.0, 1e-6]).tolist())
