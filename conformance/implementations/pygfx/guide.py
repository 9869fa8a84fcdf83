"""The FURY–pyBullet integration guide's three sync recipes, ported to FURY 2 the way a FURY user ports
them: the same algorithm, each VTK call replaced by its FURY 2 counterpart, nothing else fixed.

* :class:`GuideActorSync` — "Syncing properties of actors". ``actor.SetPosition(*pos)`` becomes
  ``actor.local.position = pos``; ``actor.SetOrientation(*np.degrees(p.getEulerFromQuaternion(orn)))``
  becomes ``actor.local.rotation = orn``: pygfx takes pyBullet's (x, y, z, w) quaternion as it is,
  so the Euler detour that FURY 0.12 needed is gone (FURY 2's ``actor.rotate`` *adds* a rotation,
  in degrees, so it is not the counterpart of ``SetOrientation``).
* :class:`GuideVertexSync` — "Rendering multiple objects by a single actor" (``sync_brick``): the
  vertex range is moved by ``getMatrixFromQuaternion(getDifferenceQuaternion(orn, old_orn))`` from
  the last pose it was drawn at. ``utils.vertices_from_actor(actor)`` becomes
  ``actor.geometry.positions.data`` (FURY 2 has no such helper) and ``utils.update_actor(actor)``
  becomes ``actor.geometry.positions.update_full()``.
* :class:`GuideJointSync` — "Rendering Joints" (``sync_joints``): the same vertex update with the pose
  from ``p.getLinkState(multibody, joint)[4:6]``.
* :class:`GuideSync` — the three combined as the guide's examples combine them.

As in the FURY 0.12 recipes, ``np.int`` became ``int`` and pybullet calls go through the scene's bound
client; each single-recipe class leaves the targets its recipe is not written for to the reference.
"""

from __future__ import annotations

from conformance.implementations.pygfx.reference import ReferenceSync
from conformance.implementations.recipes import ActorRecipe, BrickRecipe, Combined, JointRecipe

__all__ = ["GuideActorSync", "GuideJointSync", "GuideSync", "GuideVertexSync"]


class GuideActorSync(ActorRecipe):
    """The guide's actor sync on FURY 2: ``local.position = pos`` and ``local.rotation = orn``."""

    reference = ReferenceSync

    def draw(self, actor, pos, orn) -> None:
        actor.local.position = pos
        actor.local.rotation = orn


def _positions(actor):
    return actor.geometry.positions.data  # was utils.vertices_from_actor(actor)


def _update(actor) -> None:
    actor.geometry.positions.update_full()  # was utils.update_actor(actor)


class GuideVertexSync(BrickRecipe):
    """The guide's single-actor vertex sync (sync_brick) with getDifferenceQuaternion, on FURY 2."""

    reference = ReferenceSync
    vertices_of = staticmethod(_positions)
    update = staticmethod(_update)


class GuideJointSync(JointRecipe):
    """The guide's joint sync (sync_joints): vertex update with getLinkState(multibody, joint)[4:6], on FURY 2."""

    reference = ReferenceSync
    vertices_of = staticmethod(_positions)
    update = staticmethod(_update)


class GuideSync(Combined):
    """The guide's recipes combined as its examples do: actor, vertex and joint sync, on FURY 2."""

    parts = (GuideActorSync, GuideVertexSync, GuideJointSync)
