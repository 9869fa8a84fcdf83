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
the kit's reference implementation, so that its verdict measures that one recipe.
"""

from __future__ import annotations

import numpy as np
from fury import utils

from conformance.implementations.reference import ReferenceSync
from conformance.world import Target, World

__all__ = ["GuideActorSync", "GuideJointSync", "GuideSync", "GuideVertexSync"]


def _actor_recipe(t: Target) -> bool:
    return not t.shared


def _vertex_recipe(t: Target) -> bool:
    return t.shared and t.link == -1


def _joint_recipe(t: Target) -> bool:
    return t.shared and t.link >= 0


class _Recipe:
    """Runs one recipe on the targets it applies to and the reference on the rest."""

    applies = staticmethod(lambda t: False)

    def __init__(self, world: World):
        self.p = world.p
        mine = tuple(t for t in world.targets if self.applies(t))
        rest = tuple(t for t in world.targets if not self.applies(t))
        self.others = ReferenceSync(world, rest) if rest else None
        self.setup(mine)

    def setup(self, targets: tuple[Target, ...]) -> None:
        raise NotImplementedError

    def sync(self) -> None:
        raise NotImplementedError

    def __call__(self) -> None:
        self.sync()
        if self.others is not None:
            self.others()


class GuideActorSync(_Recipe):
    """The guide's actor sync: SetPosition + SetOrientation(np.degrees(getEulerFromQuaternion(orn)))."""

    applies = staticmethod(_actor_recipe)

    def setup(self, targets):
        self.targets = targets

    def sync_actor(self, actor, t: Target) -> None:
        p = self.p
        if t.link == -1:
            pos, orn = p.getBasePositionAndOrientation(t.body)
        else:
            pos, orn = p.getLinkState(t.body, t.link)[4:6]
        actor.SetPosition(*pos)
        orn_deg = np.degrees(p.getEulerFromQuaternion(orn))
        actor.SetOrientation(*orn_deg)

    def sync(self):
        for t in self.targets:
            self.sync_actor(t.actor, t)


class _VertexRecipe(_Recipe):
    """Shared state of the guide's two vertex recipes: the vertices, ``sec``, and the tracked poses."""

    def setup(self, targets):
        self.groups = []
        for actor in {id(t.actor): t.actor for t in targets}.values():
            members = [t for t in targets if t.actor is actor]
            vertices = utils.vertices_from_actor(actor)
            num_vertices = vertices.shape[0]
            num_objects = len(members)  # the guide's brick_centers.shape[0]
            sec = int(num_vertices / num_objects)  # was np.int(...), removed in numpy 1.24
            centers = np.array([t.position for t in members])
            orns = np.array([t.orientation for t in members])
            self.groups.append((actor, members, vertices, sec, centers, orns))

    def pose(self, t: Target):
        raise NotImplementedError

    def sync(self):
        p = self.p
        for actor, members, vertices, sec, centers, orns in self.groups:
            for index, t in enumerate(members):
                object_index = t.start // sec
                pos, orn = self.pose(t)
                rot_mat = np.reshape(p.getMatrixFromQuaternion(p.getDifferenceQuaternion(orn, orns[index])), (3, 3))
                vertices[object_index * sec: object_index * sec + sec] = \
                    (vertices[object_index * sec: object_index * sec + sec] - centers[index]) @ rot_mat + pos
                centers[index] = pos
                orns[index] = orn
            utils.update_actor(actor)


class GuideVertexSync(_VertexRecipe):
    """The guide's single-actor vertex sync (sync_brick) with getDifferenceQuaternion."""

    applies = staticmethod(_vertex_recipe)

    def pose(self, t):
        return self.p.getBasePositionAndOrientation(t.body)


class GuideJointSync(_VertexRecipe):
    """The guide's joint sync (sync_joints): vertex update with getLinkState(multibody, joint)[4:6]."""

    applies = staticmethod(_joint_recipe)

    def pose(self, t):
        return self.p.getLinkState(t.body, t.link)[4:6]


class GuideSync:
    """The guide's recipes combined as its examples do: actor, vertex and joint sync."""

    def __init__(self, world: World):
        self.parts = [
            GuideActorSync(_restricted(world, _actor_recipe)),
            GuideVertexSync(_restricted(world, _vertex_recipe)),
            GuideJointSync(_restricted(world, _joint_recipe)),
        ]

    def __call__(self):
        for part in self.parts:
            part()


def _restricted(world: World, keep) -> World:
    return World(scene=world.scene, p=world.p, targets=tuple(t for t in world.targets if keep(t)), actors=world.actors)
