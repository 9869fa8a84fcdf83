"""The wrong syncs whose mistake is in FURY 0.12's (VTK's) own API, for ``wrong_syncs`` to re-export.

Actor rotations and scales, vertex ranges, normals, colours and ``Modified()``, got wrong the way a
FURY 0.12 user does. Each class is ``Baseline``, this backend's ``PerTargetSync``, with the
actor-touching steps rewritten, plus a mixin from ``sync_steps`` for the part of the mistake that does
not touch the renderer. FURY 2's versions: ``wrong_syncs_pygfx``.
"""

from __future__ import annotations

import numpy as np
from fury import utils

import sync_steps
from right_syncs_vtk import PerTargetSync as Baseline  # the correct sync each mistake departs from

__all__ = ["CentreNotUpdated", "EulerRotateXYZ", "Float32Incremental", "ForgetsModified", "InflatedAgainstZFighting",
           "NormalsNotRotated", "TintsMovingBodies", "WrongVertexRange"]


# ---- rotations ---------------------------------------------------------------------------------------

class EulerRotateXYZ(Baseline):
    """Wrong: resets the actor and applies pybullet's Euler angles with RotateX, RotateY, RotateZ in
    that order. VTK's Rotate* turn about the actor's own (already turned) axes, giving Rx·Ry·Rz,
    while getEulerFromQuaternion's angles mean Rz·Ry·Rx: right only for turns about one axis. (The
    guide's SetOrientation recipe is the same mistake in VTK's Z-X-Y order.) Shared actors' vertex
    ranges are moved correctly.

    Diagnosis: euler-order
    """

    def place_whole(self, t, pos, orn):
        roll, pitch, yaw = np.degrees(self.p.getEulerFromQuaternion(orn))
        t.actor.SetOrientation(0, 0, 0)
        t.actor.RotateX(roll)
        t.actor.RotateY(pitch)
        t.actor.RotateZ(yaw)
        t.actor.SetPosition(*pos)


# ---- vertices ------------------------------------------------------------------------------------------

class InflatedAgainstZFighting(sync_steps.InflatedGeometry, Baseline):
    """Wrong: draws every body 0.1 % larger than its collision shape ("so touching bricks do not
    z-fight"): SetScale on whole actors, scaled link-frame geometry in shared ones.

    Diagnosis: -
    """

    def __init__(self, world):
        super().__init__(world)
        for t in self.targets:
            if not t.shared:
                t.actor.SetScale(self.SCALE)


class WrongVertexRange(sync_steps.ExampleVertexRanges, Baseline):
    """Wrong: FURY's wrecking-ball example bug: the guide's incremental vertex recipe with the vertices
    per object (``sec``) of every shared actor computed from the object count of the first shared
    actor (the bricks), so the other shared actors (the chain's links) are moved by the wrong ranges.
    Each actor is finished with ``utils.update_actor``, as in the example.

    Diagnosis: never-moved
    """


class CentreNotUpdated(sync_steps.StaleCentre, Baseline):
    """Wrong: the guide's incremental single-actor recipe (turn each vertex range about its tracked
    centre by the rotation since last frame, then move it to the new centre) that updates the tracked
    orientation but forgets ``brick_centers[i] = pos``: every frame turns about a stale centre.
    Each actor is finished with ``utils.update_actor``.

    Diagnosis: -
    """


class Float32Incremental(sync_steps.Float32Steps, Baseline):
    """Wrong: the incremental recipe applied to every actor's vertices (and normals) in float32 (FURY
    stores sphere vertices as float32; this keeps all its arrays so "to match VTK"): each frame's
    rotation since the last one is rounded to float32 and applied to already rounded vertices, so the
    error random-walks and a body that tumbles for thousands of steps is drawn off its pose.

    Diagnosis: -
    """


class NormalsNotRotated(sync_steps.NormalsLeftAsBuilt, Baseline):
    """Wrong: moves the vertices of shared sphere actors but leaves their stored normals as built, so a
    turned sphere is shaded as if lit from where the light was when it was built (VTK turns normals
    with an actor's matrix, never with rewritten vertices).

    Diagnosis: stale-normals
    """

    def finish(self, actors):
        for actor in actors:
            actor.GetMapper().GetInput().GetPoints().Modified()


class ForgetsModified(Baseline):
    """Wrong: writes the new vertices into the numpy view of the points but never calls
    ``utils.update_actor`` / ``Modified()``: VTK does not know the points changed and goes on
    drawing the vertices it uploaded before.

    Diagnosis: unannounced
    """

    def finish(self, actors):
        pass


# ---- side effects ----------------------------------------------------------------------------------

class TintsMovingBodies(Baseline):
    """Wrong: recolours shared-actor bodies by speed while syncing ("to see what moves"): the vertex
    colours, which a sync must leave alone, change.

    Diagnosis: -
    """

    def place_shared(self, t, pos, orn):
        super().place_shared(t, pos, orn)
        if t.link == -1:
            speed = float(np.linalg.norm(self.p.getBaseVelocity(t.body)[0]))
            colors = utils.colors_from_actor(t.actor)
            colors[t.start:t.stop, :3] = [int(255 * min(speed, 1.0)), 64, 64]
