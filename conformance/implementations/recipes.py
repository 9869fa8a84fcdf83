"""What the guide's recipes share on both backends: which targets each recipe is written for, running
one recipe with the reference sync on the rest, and combining the three as the guide's examples do.

A recipe class names its reference sync (``reference``), so that a FURY 0.12 recipe leaves the other
targets to the FURY 0.12 reference and a FURY 2 recipe to the FURY 2 one.
"""

from __future__ import annotations

import numpy as np

from conformance.world import Target, World

__all__ = ["ActorRecipe", "BrickRecipe", "Combined", "JointRecipe", "Recipe", "VertexRecipe", "actor_recipe", "joint_recipe", "vertex_recipe"]


def actor_recipe(t: Target) -> bool:
    return not t.shared and t.nodes is None  # the guide has no recipe for soft bodies: the reference draws them


def vertex_recipe(t: Target) -> bool:
    return t.shared and t.link == -1


def joint_recipe(t: Target) -> bool:
    return t.shared and t.link >= 0


class Recipe:
    """Runs one recipe on the targets it applies to and ``reference`` on the rest."""

    applies = staticmethod(lambda t: False)
    reference = None  # the backend's ReferenceSync class

    def __init__(self, world: World):
        self.p = world.p
        mine = tuple(t for t in world.targets if self.applies(t))
        rest = tuple(t for t in world.targets if not self.applies(t))
        self.others = type(self).reference(world, rest) if rest else None
        self.setup(mine)

    def setup(self, targets: tuple[Target, ...]) -> None:
        raise NotImplementedError

    def sync(self) -> None:
        raise NotImplementedError

    def __call__(self) -> None:
        self.sync()
        if self.others is not None:
            self.others()


class ActorRecipe(Recipe):
    """The guide's actor recipe ("Syncing properties of actors"): each whole actor gets the pose its
    body reports, ``getBasePositionAndOrientation`` for a base, ``getLinkState(body, link)[4:6]`` for a
    link, through ``draw(actor, pos, orn)``, which a backend writes in its FURY's calls."""

    applies = staticmethod(actor_recipe)

    def setup(self, targets):
        self.targets = targets

    def draw(self, actor, pos, orn) -> None:
        raise NotImplementedError

    def sync_actor(self, actor, t: Target) -> None:
        p = self.p
        if t.link == -1:
            pos, orn = p.getBasePositionAndOrientation(t.body)
        else:
            pos, orn = p.getLinkState(t.body, t.link)[4:6]
        self.draw(actor, pos, orn)

    def sync(self):
        for t in self.targets:
            self.sync_actor(t.actor, t)


class VertexRecipe(Recipe):
    """The guide's vertex recipes (``sync_brick``, ``sync_joints``) as written: each vertex range is
    moved by ``getMatrixFromQuaternion(getDifferenceQuaternion(orn, old_orn))`` about its tracked
    centre, from the last pose it was drawn at. A backend names how the guide's two FURY calls are
    spelt there: ``vertices_of`` (``utils.vertices_from_actor``) and ``update`` (``utils.update_actor``)."""

    vertices_of = None
    update = None

    def setup(self, targets):
        self.groups = []
        for actor in {id(t.actor): t.actor for t in targets}.values():
            members = [t for t in targets if t.actor is actor]
            vertices = type(self).vertices_of(actor)
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
            type(self).update(actor)


class BrickRecipe(VertexRecipe):
    """The guide's single-actor vertex sync (``sync_brick``): bodies in shared actors, their base pose."""

    applies = staticmethod(vertex_recipe)

    def pose(self, t):
        return self.p.getBasePositionAndOrientation(t.body)


class JointRecipe(VertexRecipe):
    """The guide's joint sync (``sync_joints``): links in shared actors, ``getLinkState(multibody, joint)[4:6]``."""

    applies = staticmethod(joint_recipe)

    def pose(self, t):
        return self.p.getLinkState(t.body, t.link)[4:6]


class Combined:
    """The three recipes as the guide's examples combine them: whole actors by the actor recipe, bodies
    sharing an actor by the vertex recipe, links sharing an actor by the joint recipe. A backend names
    its three recipe classes."""

    parts = ()

    def __init__(self, world: World):
        keeps = (actor_recipe, vertex_recipe, joint_recipe)
        self.syncs = [part(_restricted(world, keep)) for part, keep in zip(type(self).parts, keeps)]

    def __call__(self) -> None:
        for sync in self.syncs:
            sync()


def _restricted(world: World, keep) -> World:
    return World(scene=world.scene, p=world.p, targets=tuple(t for t in world.targets if keep(t)), actors=world.actors)
