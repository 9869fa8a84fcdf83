"""The floor: the least a sync must do each frame, written as a sync (it follows the protocol).

Every pose read once with plain pybullet calls
(``pybullet.getBasePositionAndOrientation(b, physicsClientId=c)`` for a base,
``pybullet.getLinkState(b, l, computeForwardKinematics=1, physicsClientId=c)`` for a link), plus the
least that tells the renderer something changed (:mod:`.backend`, for the backend in force):

* per shared actor, one pass over its vertex array: one numpy write of vertices prepared at set-up
  (and of its normals, if it stores any) and the announcement: ``Modified()`` on FURY 0.12 (VTK),
  ``update_full()`` on FURY 2 (pygfx);
* per whole actor, the one Python call a sync cannot avoid making per actor. On FURY 0.12, one
  ``SetUserMatrix`` of a ``vtkMatrix4x4`` prepared at set-up, the same one every frame: after the
  first, VTK returns at once. On FURY 2, one ``actor.local.position = p`` of a position prepared at
  set-up: of ``local.position =`` and ``local.matrix =``, the cheaper by far (measured at 1,000 actors: ~0.4-0.6
  µs a body, against ~18-19 µs for ``actor.local.matrix = M``, which pygfx decomposes into position,
  rotation and scale on every call; ``local.rotation = q`` costs as much as ``local.position``; the
  reads table times them in every run). pygfx has no early return: every call writes the position
  and flags the transform changed, so unlike VTK's this write is paid every frame.

Nothing is computed from the poses, so the floor draws nothing right: it is a yardstick, not a
sync. Every sync figure of the bench is a ratio to it, measured in the same run and process.
"""

from __future__ import annotations

import pybullet

from conformance.world import World

from . import backend

__all__ = ["DEFINITION", "Floor"]

#: The floor in one sentence, for the tables: the floor of the backend in force.
DEFINITION = ("every pose read once with plain pybullet calls (`pybullet.getBasePositionAndOrientation(b, "
              "physicsClientId=c)`), " + backend.FLOOR_WRITES)


class Floor:
    """Reads every pose once, writes each shared actor once and makes each whole actor's one call."""

    def __init__(self, world: World):
        self.client = world.client
        self.bases = [t.body for t in world.targets if t.link == -1]
        self.links = [(t.body, t.link) for t in world.targets if t.link >= 0]
        self.write_whole = backend.whole_writes([t.actor for t in world.targets if not t.shared])
        self.write_shared = backend.shared_writes(list({id(t.actor): t.actor for t in world.targets if t.shared}.values()))

    def __call__(self) -> None:
        client = self.client
        for body in self.bases:
            pybullet.getBasePositionAndOrientation(body, physicsClientId=client)
        for body, link in self.links:
            pybullet.getLinkState(body, link, computeForwardKinematics=1, physicsClientId=client)
        self.write_shared()
        self.write_whole()
