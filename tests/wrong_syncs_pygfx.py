"""The wrong syncs whose mistake is in FURY 2's (pygfx's) own API, for ``wrong_syncs`` to re-export.

A FURY 2 user makes these with ``actor.local`` (where VTK has the actor matrix), with
``geometry.positions.data`` (where FURY 0.12 has ``utils.vertices_from_actor``) and by announcing
buffers with ``update_range``/``update_full`` (VTK: ``Modified()``). Each class is ``Baseline``, this
backend's ``PerTargetSync``, with the actor-touching steps rewritten, plus a mixin from ``sync_steps``
for the part of the mistake that does not touch the renderer. FURY 0.12's versions: ``wrong_syncs_vtk``.
"""

from __future__ import annotations

import numpy as np

import sync_steps
from right_syncs_pygfx import PerTargetSync as Baseline  # the correct sync each mistake departs from

__all__ = ["AnnouncesLastRangeOnly", "CentreNotUpdated", "EulerRotateXYZ", "Float32Incremental", "ForgetsModified",
           "InflatedAgainstZFighting", "NormalsNotRotated", "NormalsUnannounced", "TintsMovingBodies", "WrongVertexRange"]


# ---- rotations ---------------------------------------------------------------------------------------

class EulerRotateXYZ(Baseline):
    """Wrong: resets the actor's rotation and applies pybullet's Euler angles with FURY 2's
    ``actor.rotate`` one axis at a time, yaw first, then pitch, then roll (the "yaw-pitch-roll"
    reading of getEulerFromQuaternion's Z-Y-X convention). FURY 2's rotate turns about the *world*
    axes (it pre-multiplies ``local.matrix``), not the actor's own as VTK's RotateX/Y/Z do, giving
    Rx·Ry·Rz, while the angles mean Rz·Ry·Rx: right only for turns about one axis. (The VTK
    mistake's order, roll first, happens to be right on FURY 2, as is ``actor.rotate((roll, pitch,
    yaw))`` or ``local.euler`` in radians.) Shared actors' vertex ranges are moved correctly.

    Diagnosis: euler-order
    """

    def place_whole(self, t, pos, orn):
        roll, pitch, yaw = np.degrees(self.p.getEulerFromQuaternion(orn))
        t.actor.local.rotation = (0, 0, 0, 1)
        t.actor.rotate((0, 0, yaw))  # degrees, each about the world axis, after what is there
        t.actor.rotate((0, pitch, 0))
        t.actor.rotate((roll, 0, 0))
        t.actor.local.position = pos


# ---- vertices ------------------------------------------------------------------------------------------

class InflatedAgainstZFighting(sync_steps.InflatedGeometry, Baseline):
    """Wrong: draws every body 0.1 % larger than its collision shape ("so touching bricks do not
    z-fight"): ``local.scale`` on whole actors, scaled link-frame geometry in shared ones.

    Diagnosis: -
    """

    def place_whole(self, t, pos, orn):
        super().place_whole(t, pos, orn)
        t.actor.local.scale = self.SCALE  # after the pose: setting local.matrix replaces the scale too


class WrongVertexRange(sync_steps.ExampleVertexRanges, Baseline):
    """Wrong: FURY's wrecking-ball example bug: the guide's incremental vertex recipe with the vertices
    per object (``sec``) of every shared actor computed from the object count of the first shared
    actor (the bricks), so the other shared actors (the chain's links) are moved by the wrong ranges.

    Diagnosis: never-moved
    """

    def finish(self, actors):
        for actor in actors:
            self.announce(actor)  # was utils.update_actor(actor): positions and normals


class CentreNotUpdated(sync_steps.StaleCentre, Baseline):
    """Wrong: the guide's incremental single-actor recipe (turn each vertex range about its tracked
    centre by the rotation since last frame, then move it to the new centre) that updates the tracked
    orientation but forgets ``brick_centers[i] = pos``: every frame turns about a stale centre.

    Diagnosis: -
    """

    def place_shared(self, t, pos, orn):
        super().place_shared(t, pos, orn)
        self.announce_range(t)  # positions and normals

    def place_soft(self, t):
        super().place_soft(t)
        self.announce_range(t)  # so that a soft body's nodes are announced too: the mistake is the centre alone

    def finish(self, actors):
        pass  # each range was announced as it was written


class Float32Incremental(sync_steps.Float32Steps, Baseline):
    """Wrong: the incremental recipe applied to every actor's vertices (and normals) in float32 (FURY 2
    stores every actor's positions as float32; this keeps all its arrays so "to match the GPU"): each
    frame's rotation since the last one is rounded to float32 and applied to already rounded vertices,
    so the error random-walks and a body that tumbles for thousands of steps is drawn off its pose.

    Diagnosis: -
    """


class NormalsNotRotated(sync_steps.NormalsLeftAsBuilt, Baseline):
    """Wrong: moves the vertices of shared sphere actors but leaves their ``geometry.normals`` as built,
    so a turned sphere is shaded as if lit from where the light was when it was built (pygfx turns
    normals with an actor's world matrix, never with rewritten positions, and never recomputes a
    normals buffer it was given).

    Diagnosis: stale-normals
    """

    def finish(self, actors):
        for actor in actors:
            actor.geometry.positions.update_full()


class ForgetsModified(Baseline):
    """Wrong: writes the new vertices into ``geometry.positions.data`` but never calls
    ``update_range``/``update_full``: pygfx does not know the buffer changed and goes on drawing the
    vertices it uploaded before.

    Diagnosis: unannounced
    """

    def finish(self, actors):
        pass


class NormalsUnannounced(Baseline):
    """Wrong: turns the normals with the vertices but announces only ``geometry.positions``: pygfx uploads
    each buffer on its own, so the normals on screen stay as they were and a turned sphere is lit as
    before (the kit's vertex and normals read-back sees the buffers, not what was uploaded).

    Diagnosis: unannounced
    """

    def finish(self, actors):
        for actor in actors:
            actor.geometry.positions.update_full()


class AnnouncesLastRangeOnly(Baseline):
    """Wrong: announces one range per shared actor after the loop, with the loop's last target
    (``update_range(t.start, t.stop - t.start)`` dedented one level): every other body's vertices
    change in a buffer whose changed chunks pygfx is never told about.

    Diagnosis: unannounced
    """

    def place_shared(self, t, pos, orn):
        super().place_shared(t, pos, orn)
        self.last = t

    def place_soft(self, t):
        super().place_soft(t)
        self.announce_range(t)  # a soft body's actor is its own: its one range is the last (the mistake is in shared ones)

    def finish(self, actors):
        last = getattr(self, "last", None)
        for actor in actors:
            if last is not None and last.actor is actor:
                self.announce_range(last)


# ---- side effects ----------------------------------------------------------------------------------

class TintsMovingBodies(Baseline):
    """Wrong: recolours shared-actor bodies by speed while syncing ("to see what moves"): the vertex
    colours (``geometry.colors``, announced with ``update_range``), which a sync must leave alone, change.

    Diagnosis: -
    """

    def place_shared(self, t, pos, orn):
        super().place_shared(t, pos, orn)
        if t.link == -1:
            speed = float(np.linalg.norm(self.p.getBaseVelocity(t.body)[0]))
            colors = t.actor.geometry.colors
            colors.data[t.start:t.stop, :3] = [min(speed, 1.0), 0.25, 0.25]
            colors.update_range(t.start, t.stop - t.start)
