"""Right syncs written before soft bodies: each hands every target, a soft body's too, to its pose code, as
the protocol allowed before ``Target.nodes``. They draw every rigid body right; on the soft scenes
(``cloth``, ``soft_ball``) they fail, and ``tests/test_soft_opt_out.py`` holds the kit to saying why, and to
running every other check when soft scenes are left out (``-m "not soft"``).

Each is a right sync of the kit's handed a world whose targets say nothing of nodes (``nodes=None``), so the
soft body is drawn the rigid way, and nothing else changes."""

from __future__ import annotations

import dataclasses

from conformance.implementations.reference import ReferenceSync

__all__ = ["LeavesSoftBodiesAlone", "PosesEveryTarget", "rewrites_every_target"]


def _as_before(world):
    """``world`` as a sync written before soft bodies sees it: no target follows nodes."""
    return dataclasses.replace(world, targets=tuple(dataclasses.replace(t, nodes=None) for t in world.targets))


class PosesEveryTarget(ReferenceSync):
    """The reference sync from before soft bodies: each whole actor, a soft body's too, gets its target's
    link-frame pose as its transform; shared actors get their vertex ranges rewritten."""

    def __init__(self, world):
        super().__init__(_as_before(world))


def rewrites_every_target(world):
    """``right_syncs.vectorised_vertex_sync`` from before soft bodies: every actor's vertices, a soft body's too,
    rewritten at its target's link frame (the transforms left alone)."""
    import right_syncs

    return right_syncs.vectorised_vertex_sync(_as_before(world))


class LeavesSoftBodiesAlone(ReferenceSync):
    """The reference sync handed the rigid targets only, as a sync that draws what it knows and leaves the
    rest: a soft body stays drawn as it was built."""

    def __init__(self, world):
        super().__init__(world, tuple(t for t in world.targets if t.nodes is None))
