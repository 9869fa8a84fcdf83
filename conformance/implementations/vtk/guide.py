"""The FURY–pyBullet integration guide's three sync recipes, reproduced as written.

Only what no longer runs was modernised: ``np.int(...)`` became ``int(...)``, and pybullet calls go
through the scene's bound client (``p = world.p``) instead of the implicit default client. Whether
the recipes are right is for the conformance checks to say; these classes do not fix them.

* :class:`GuideActorSync` — "Syncing properties of actors": ``SetPosition`` and ``SetOrientation``
  with ``np.degrees(p.getEulerFromQuaternion(orn))`` (the guide's ``sync_actor``).
* :class:`GuideVertexSync` — "Rendering multiple objects by a single actor": the vertex range is
  moved by ``getMatrixFromQuaternion(getDifferenceQuaternion(orn, old_orn))`` from the last pose
  it was drawn at (the guide's ``sync_brick``).
* :class:`GuideJointSync` — "Rendering Joints": the same vertex update with the pose from
  ``p.getLinkState(multibody, joint)[4:6]`` (the guide's ``sync_joints``).
* :class:`GuideSync` — the three combined as the guide's examples combine them: whole actors by the
  actor recipe, bodies sharing an actor by the vertex recipe, links sharing an actor by the joint
  recipe.

Each single-recipe class moves only the targets its recipe is written for and leaves the others to
the kit's reference implementation, so that its verdict measures that one recipe. The recipes' steps,
the same on both FURYs, are in :mod:`conformance.implementations.recipes`; this module spells the
guide's FURY 0.12 calls (``SetPosition``/``SetOrientation``, ``utils.vertices_from_actor``,
``utils.update_actor``).
"""

from __future__ import annotations

import numpy as np
from fury import utils

from conformance.implementations.vtk.reference import ReferenceSync
from conformance.implementations.recipes import ActorRecipe, BrickRecipe, Combined, JointRecipe

__all__ = ["GuideActorSync", "GuideJointSync", "GuideSync", "GuideVertexSync"]


class GuideActorSync(ActorRecipe):
    """The guide's actor sync: SetPosition + SetOrientation(np.degrees(getEulerFromQuaternion(orn)))."""

    reference = ReferenceSync

    def draw(self, actor, pos, orn) -> None:
        actor.SetPosition(*pos)
        orn_deg = np.degrees(self.p.getEulerFromQuaternion(orn))
        actor.SetOrientation(*orn_deg)


class GuideVertexSync(BrickRecipe):
    """The guide's single-actor vertex sync (sync_brick) with getDifferenceQuaternion."""

    reference = ReferenceSync
    vertices_of = staticmethod(utils.vertices_from_actor)
    update = staticmethod(utils.update_actor)


class GuideJointSync(JointRecipe):
    """The guide's joint sync (sync_joints): vertex update with getLinkState(multibody, joint)[4:6]."""

    reference = ReferenceSync
    vertices_of = staticmethod(utils.vertices_from_actor)
    update = staticmethod(utils.update_actor)


class GuideSync(Combined):
    """The guide's recipes combined as its examples do: actor, vertex and joint sync."""

    parts = (GuideActorSync, GuideVertexSync, GuideJointSync)
