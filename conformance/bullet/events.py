"""Things that happen to a scene between syncs: teleports, joint resets and kicks, of rigid and soft bodies.

Each event is applied before the step of its frame (so frame ``n``'s sync sees its effect); a
teleport at frame 0 moves a body after the actors were built and before the first sync. Events
name their body by position in the scene's list of bodies (``which``, taken modulo that list's
length), so a Hypothesis-drawn event fits any scene. Events round-trip through JSON so that a
failure's "reproduce:" line can replay them.
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass
from typing import Sequence

import pybullet

__all__ = ["LIFT", "Event", "JointReset", "Kick", "SoftKick", "SoftTeleport", "Teleport", "dumps", "loads",
           "turning_everything"]


def _bodies(scene) -> list[int]:
    """The rigid bodies :class:`Teleport`, :class:`Kick` and :class:`JointReset` act on."""
    return sorted({b.body for b in scene.bindings if not b.soft})


def _soft_bodies(scene) -> list[int]:
    """The soft bodies :class:`SoftTeleport` and :class:`SoftKick` act on."""
    return sorted({b.body for b in scene.bindings if b.soft})


def _joints(scene) -> list[tuple[int, int]]:
    """(body, joint) pairs of revolute, prismatic and spherical joints: those ``resetJoint*`` moves."""
    found = []
    for body in _bodies(scene):
        for joint in range(scene.p.getNumJoints(body)):
            kind = scene.p.getJointInfo(body, joint)[2]
            if kind in (pybullet.JOINT_REVOLUTE, pybullet.JOINT_PRISMATIC, pybullet.JOINT_SPHERICAL):
                found.append((body, joint))
    return found


@dataclass(frozen=True)
class Teleport:
    """``resetBasePositionAndOrientation`` of a body to ``position``/``orientation`` (relative to where
    it is, for ``position``, so that a teleported body stays in view). No-op without rigid bodies."""

    frame: int
    which: int
    offset: tuple[float, float, float]
    orientation: tuple[float, float, float, float]

    def apply(self, scene) -> None:
        _teleport(scene, _bodies(scene), self.which, self.offset, self.orientation)


def _teleport(scene, bodies: list[int], which: int, offset, orientation) -> None:
    """``resetBasePositionAndOrientation`` of body ``which`` (modulo) of ``bodies`` by ``offset`` from where it is, to
    ``orientation``; nothing without bodies (a world of soft bodies, or of static ones in an app)."""
    if not bodies:
        return
    body = bodies[which % len(bodies)]
    pos, _ = scene.p.getBasePositionAndOrientation(body)
    scene.p.resetBasePositionAndOrientation(body, [a + b for a, b in zip(pos, offset)], list(orientation))


@dataclass(frozen=True)
class JointReset:
    """``resetJointState`` (or ``resetJointStateMultiDof`` for a spherical joint) to ``value``: an angle
    or distance, or the quaternion ``orientation`` for spherical joints. No-op in a scene without joints."""

    frame: int
    which: int
    value: float
    orientation: tuple[float, float, float, float]

    def apply(self, scene) -> None:
        joints = _joints(scene)
        if not joints:
            return
        body, joint = joints[self.which % len(joints)]
        if scene.p.getJointInfo(body, joint)[2] == pybullet.JOINT_SPHERICAL:
            scene.p.resetJointStateMultiDof(body, joint, targetValue=list(self.orientation), targetVelocity=[0, 0, 0])
        else:
            scene.p.resetJointState(body, joint, self.value)


@dataclass(frozen=True)
class Kick:
    """One step of ``applyExternalForce`` (at ``offset`` from the centre of mass) and
    ``applyExternalTorque``, both WORLD_FRAME, sized to change the base's velocity by about
    ``velocity`` (m/s) and its angular velocity by about ``spin`` (rad/s): sets a body moving and
    spinning whatever its mass and inertia. No-op without rigid bodies."""

    frame: int
    which: int
    velocity: tuple[float, float, float]
    offset: tuple[float, float, float]
    spin: tuple[float, float, float]

    def apply(self, scene) -> None:
        from conformance.bullet import poses

        bodies = _bodies(scene)
        if not bodies:
            return
        body = bodies[self.which % len(bodies)]
        info = scene.p.getDynamicsInfo(body, -1)
        mass, inertia = info[0], info[2]
        if mass == 0:
            return  # a static body ignores forces
        dt = scene.dt
        pos, orn = scene.p.getBasePositionAndOrientation(body)
        # The COM frame is the principal-axes frame, so I_world = R diag(I) Rᵀ.
        rotation = poses.matrices(orn)
        torque = rotation @ (list(inertia) * (rotation.T @ self.spin)) / dt
        scene.p.applyExternalForce(body, -1, [mass * v / dt for v in self.velocity],
                                   [a + b for a, b in zip(pos, self.offset)], pybullet.WORLD_FRAME)
        scene.p.applyExternalTorque(body, -1, [float(t) for t in torque], pybullet.WORLD_FRAME)


@dataclass(frozen=True)
class SoftTeleport:
    """``resetBasePositionAndOrientation`` of a soft body, which moves and turns every node as one rigid piece
    (measured on pybullet 3.2.7, cloth, soft ball and both jelly blocks: the nodes' centroid goes to the
    position given, the nodes turn by the orientation given times the inverse of the one
    ``getBasePositionAndOrientation`` reports, and keep their shape to 1e-15 m). Here the centroid moves by
    ``offset`` (its height by ``abs(offset[2])``, so that a body is never pushed into the ground) and the body
    turns to ``orientation``. No-op in a scene without soft bodies."""

    frame: int
    which: int
    offset: tuple[float, float, float]
    orientation: tuple[float, float, float, float]

    def apply(self, scene) -> None:
        dx, dy, dz = self.offset
        _teleport(scene, _soft_bodies(scene), self.which, (dx, dy, abs(dz)), self.orientation)


@dataclass(frozen=True)
class SoftKick:
    """``resetBaseVelocity`` of a soft body to ``velocity`` (m/s): every node's velocity is set to it (measured:
    1 m/s moves each node 1/240 m in the next step of 1/240 s). pyBullet offers no other push: forces
    (``applyExternalForce``) do nothing to a soft body. No-op in a scene without soft bodies."""

    frame: int
    which: int
    velocity: tuple[float, float, float]

    def apply(self, scene) -> None:
        bodies = _soft_bodies(scene)
        if bodies:
            scene.p.resetBaseVelocity(bodies[self.which % len(bodies)], list(self.velocity), [0.0, 0.0, 0.0])


Event = Teleport | JointReset | Kick | SoftTeleport | SoftKick
_KINDS = {"teleport": Teleport, "joint_reset": JointReset, "kick": Kick, "soft_teleport": SoftTeleport,
          "soft_kick": SoftKick}


def dumps(events: Sequence[Event]) -> str:
    names = {cls: name for name, cls in _KINDS.items()}
    return json.dumps([{"kind": names[type(e)], **asdict(e)} for e in events], separators=(",", ":"))


def loads(text: str) -> list[Event]:
    from conformance.errors import InvalidArgument

    try:
        items = json.loads(text)
        events = []
        for item in items:
            item = dict(item)
            cls = _KINDS[item.pop("kind")]
            events.append(cls(**{k: tuple(v) if isinstance(v, list) else v for k, v in item.items()}))
    except (ValueError, KeyError, TypeError) as exc:
        raise InvalidArgument(f"events={text[:200]!r} is not a list of events as the kit writes them ({exc})") from None
    for e in events:
        values = [v for v in asdict(e).values() for v in (v if isinstance(v, tuple) else (v,))]
        if not all(math.isfinite(v) for v in values):
            raise InvalidArgument(f"event {e!r} has a non-finite value")
    return events


#: How far every body is lifted when it is turned again at frame 1 (so that it moves even if its turn does not).
LIFT = (0.0, 0.0, 0.05)


def turning_everything(bodies: int, turns, soft_bodies: int = 0) -> list:
    """Events turning every one of ``bodies`` rigid bodies, static ones too, every one of ``soft_bodies`` soft
    bodies, and every joint to the orientations ``turns`` (cycled) at frame 0, before the first sync; and
    turning every body again (``turns`` reversed) and lifting it a little at frame 1, after the first sync:
    a body the sync places once, or only while it has velocity, is then drawn where it was, and a soft body
    drawn in the frame it was loaded in is drawn turned the wrong way (the orientation check's events)."""
    again = turns[::-1]
    events: list = [Teleport(0, i, (0.0, 0.0, 0.0), turns[i % len(turns)]) for i in range(bodies)]
    events += [SoftTeleport(0, i, (0.0, 0.0, 0.0), turns[i % len(turns)]) for i in range(soft_bodies)]
    events += [JointReset(0, i, 1.0, turns[i % len(turns)]) for i in range(8)]
    events += [Teleport(1, i, LIFT, again[i % len(again)]) for i in range(bodies)]
    return events + [SoftTeleport(1, i, LIFT, again[i % len(again)]) for i in range(soft_bodies)]
