"""A scene's physics state at one frame, as plain data: captured, restored, compared.

A golden snapshot stores the state of the frame it shows (:mod:`conformance.rendering.golden`), so
that its two verdicts can be told apart: *render* restores the stored state, syncs and renders,
which judges the sync and the renderer whatever pyBullet does on this machine; *physics* compares
a live run's state with the stored one, which tells a pyBullet or platform change from a rendering
change.

The state holds, for every body, what pyBullet needs to put it back exactly: the base's centre-of-mass
pose and velocity (``resetBasePositionAndOrientation``/``resetBaseVelocity``, PyBullet Quickstart
Guide, "Base, Joint, Link"), and each joint's multi-DOF position and velocity
(``resetJointStateMultiDof``); and, for every drawn target, its link-frame pose (what a sync draws).
Floats go through JSON as ``repr`` does, shortest round-trip, so a stored state restores bit for bit.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from conformance.bullet import truth

__all__ = ["FLOAT_NOISE", "NOISE_SHARE", "NOISE_STEP", "FloatNoise", "PhysicsDifference", "capture", "compare", "float_noise",
           "nudged", "restore"]

#: Physics verdict: a live target farther than this from its stored link-frame pose is a difference.
#: On one machine pyBullet is bit-identical run to run (``test_scenes`` proves it), so any figure
#: above zero means another pyBullet, platform or compiler; 1 µm and 1e-5 rad keep last-bit float
#: noise from another platform quiet while a real change in physics (a step, a parameter) shows.
POSITION_TOLERANCE = 1e-6
ANGLE_TOLERANCE = 1e-5

#: Regeneration: a fresh state whose every float is within this share of the physics verdict's tolerance
#: of the stored state's differs by float noise only, and the stored golden is kept. Each float counts
#: against the tolerance of what it is: a position against 1 µm, a quaternion component (twice it, the
#: angle it turns by) against 1e-5 rad, a velocity by how far it moves a pose in one step
#: (:data:`NOISE_STEP`), a joint position against the stricter of the two (its unit is m or rad).
#: pyBullet computes in float64, bit-identical run to run on one machine; another CPU running the same
#: build may round a few operations differently (its libm's sin, cos, sqrt or pow off by an ulp, a·b+c
#: fused into one FMA or not), which moves the last bits: weighted's 0.041971097911914286 came back as
#: 0.04197109791191429, 7e-18 apart, and where a scene's physics amplifies it, more (measured: this
#: machine against the goldens another made, weighted's frame 480: 3.3e-8 m in a target's position,
#: 3.3 % of the tolerance). A golden kept for a tenth of the tolerance judges the physics as a
#: rewritten one would to that tenth; its pictures are the same pixels, or it is written.
NOISE_SHARE = 0.1
#: The same bound for a position, in metres.
FLOAT_NOISE = POSITION_TOLERANCE * NOISE_SHARE
#: The step over which a velocity's difference is counted: the guide's 240 Hz, the scenes' default.
NOISE_STEP = 1.0 / 240.0


def capture(scene) -> dict[str, Any]:
    """Every body's base pose, velocity and joint states (a soft body's nodes), and every target's link-frame pose."""
    p = scene.p
    soft = {b.body for b in scene.bindings if b.soft}
    bodies = []
    for i in range(p.getNumBodies()):
        body = p.getBodyUniqueId(i)
        position, orientation = p.getBasePositionAndOrientation(body)
        linear, angular = p.getBaseVelocity(body)
        joints = []
        for j in range(p.getNumJoints(body)):
            q, qdot = p.getJointStateMultiDof(body, j)[:2]
            joints.append({"position": list(q), "velocity": list(qdot)})
        entry = {"body": body, "position": list(position), "orientation": list(orientation),
                 "linear_velocity": list(linear), "angular_velocity": list(angular), "joints": joints}
        if body in soft:
            entry["nodes"] = truth.nodes(p, body).tolist()
        bodies.append(entry)
    positions, orientations = truth.link_frames(p, truth.items_of(scene.bindings))
    targets = [{"name": b.name, "body": b.body, "link": b.link, "position": positions[i].tolist(),
                "orientation": orientations[i].tolist()} for i, b in enumerate(scene.bindings)]
    return {"bodies": bodies, "targets": targets}


def restore(scene, state: dict[str, Any]) -> None:
    """Put every body of ``scene`` back in ``state`` (from :func:`capture` on the same scene)."""
    p = scene.p
    for entry in state["bodies"]:
        body = entry["body"]
        if "nodes" in entry:
            # A soft body's nodes, put back bit for bit (measured); pyBullet has no call that sets their velocities,
            # so a restored soft body is right for a picture, not for stepping on.
            p.resetMeshData(body, vertices=entry["nodes"])
            continue
        p.resetBasePositionAndOrientation(body, entry["position"], entry["orientation"])
        p.resetBaseVelocity(body, entry["linear_velocity"], entry["angular_velocity"])
        for j, joint in enumerate(entry["joints"]):
            if joint["position"] or joint["velocity"]:  # fixed joints have no degrees of freedom
                p.resetJointStateMultiDof(body, j, joint["position"], joint["velocity"])


@dataclass(frozen=True)
class PhysicsDifference:
    """The largest difference between two states' target poses (the physics verdict)."""

    position: float  # metres
    angle: float  # radians
    target: str  # the target where the larger of the two (relative to its tolerance) was seen

    @property
    def ok(self) -> bool:
        return self.position <= POSITION_TOLERANCE and self.angle <= ANGLE_TOLERANCE

    def describe(self) -> str:
        return (f"largest difference at {self.target!r}: {self.position:.3g} m (tolerance {POSITION_TOLERANCE:g} m), "
                f"{self.angle:.3g} rad (tolerance {ANGLE_TOLERANCE:g} rad)")

    def as_dict(self) -> dict[str, Any]:
        return {"position": self.position, "angle": self.angle, "target": self.target, "ok": self.ok,
                "position_tolerance": POSITION_TOLERANCE, "angle_tolerance": ANGLE_TOLERANCE}


def compare(live: dict[str, Any], stored: dict[str, Any]) -> PhysicsDifference:
    """How far ``live`` targets are from ``stored`` ones (the same scene, the same targets)."""
    a, b = live["targets"], stored["targets"]
    if [t["name"] for t in a] != [t["name"] for t in b]:
        return PhysicsDifference(float("inf"), float("inf"), "(the targets differ: other scene parameters?)")
    names = {t["body"]: t["name"] for t in a}
    for x, y in zip(live["bodies"], stored["bodies"]):
        if "nodes" in x or "nodes" in y:  # a soft body: its nodes are its pose
            if len(x.get("nodes", ())) != len(y.get("nodes", ())):
                return PhysicsDifference(float("inf"), float("inf"), f"{names.get(x['body'], x['body'])!r} (other nodes)")
            far = float(np.linalg.norm(np.subtract(x["nodes"], y["nodes"]), axis=1).max(initial=0.0))
            if far > POSITION_TOLERANCE:
                return PhysicsDifference(far, 0.0, f"{names.get(x['body'], x['body'])!r} (its nodes)")
    pa = np.array([t["position"] for t in a], dtype=float)
    pb = np.array([t["position"] for t in b], dtype=float)
    qa = np.array([t["orientation"] for t in a], dtype=float)
    qb = np.array([t["orientation"] for t in b], dtype=float)
    distances = np.linalg.norm(pa - pb, axis=1)
    # pyBullet's quaternions are float32 values, a few 1e-8 off unit length, so acos(|q_a · q_b|) of
    # two equal ones reads ~1e-4 rad; 2·atan2(|q_a − s q_b|, |q_a + s q_b|) of unit quaternions (s the
    # sign that makes them the same hemisphere: q and −q are one rotation) is exact for equal ones.
    qa /= np.linalg.norm(qa, axis=1, keepdims=True)
    qb /= np.linalg.norm(qb, axis=1, keepdims=True)
    signs = np.where(np.sum(qa * qb, axis=1) < 0, -1.0, 1.0)[:, None]
    angles = 2.0 * np.arctan2(np.linalg.norm(qa - signs * qb, axis=1), np.linalg.norm(qa + signs * qb, axis=1))
    score = np.maximum(distances / POSITION_TOLERANCE, angles / ANGLE_TOLERANCE)
    worst = int(np.argmax(score)) if len(score) else 0
    return PhysicsDifference(float(distances.max(initial=0.0)), float(angles.max(initial=0.0)),
                             a[worst]["name"] if a else "")


def nudged(scene, distance: float = 1e-9) -> None:
    """Move every dynamic body's base (every soft body's nodes) by ``distance`` along x, keeping its velocity
    (a reset alone zeroes it): the smallest difference another platform's floating point could make."""
    p = scene.p
    soft = {b.body for b in scene.bindings if b.soft}
    for i in range(p.getNumBodies()):
        body = p.getBodyUniqueId(i)
        if body in soft:  # every node; resetMeshData keeps the nodes' velocities (measured: a reset to itself changes nothing)
            p.resetMeshData(body, vertices=(truth.nodes(p, body) + [distance, 0.0, 0.0]).tolist())
        elif p.getDynamicsInfo(body, -1)[0] > 0:
            (x, y, z), orientation = p.getBasePositionAndOrientation(body)
            linear, angular = p.getBaseVelocity(body)
            p.resetBasePositionAndOrientation(body, [x + distance, y, z], orientation)
            p.resetBaseVelocity(body, linear, angular)


@dataclass(frozen=True)
class FloatNoise:
    """The float of two states (alike in all else) that differs most for its tolerance."""

    largest: float  # its difference, in its own unit
    where: str  # its path in the state, e.g. "bodies[1].position[0]"
    share: float = 0.0  # that difference as a share of the physics tolerance of its kind

    @property
    def is_noise(self) -> bool:
        return self.share <= NOISE_SHARE

    def describe(self) -> str:
        return (f"largest difference {self.largest:.3g} at {self.where}, {100 * self.share:.2g} % of the physics "
                f"tolerance (bound {100 * NOISE_SHARE:g} %)")


def _share(where: str, difference: float) -> float:
    """``difference`` of the float at ``where`` as a share of the physics verdict's tolerance for it."""
    name = where.rsplit(".", 1)[-1].split("[")[0]
    if "velocity" in name:  # m/s, rad/s: what it moves a pose by in one step
        difference *= NOISE_STEP
    angular = "orientation" in name or name == "angular_velocity"
    if "orientation" in name:
        difference *= 2.0  # a quaternion component's change turns by up to twice as much
    return difference / (ANGLE_TOLERANCE if angular else POSITION_TOLERANCE)


def float_noise(new: Any, old: Any) -> FloatNoise | None:
    """How far apart the floats of two states are (as JSON holds them: lists, not tuples), or None
    when they differ in anything else: other bodies, joints, targets, names, ids, or a float where
    the other has none. Equal floats of another sign of zero differ by 0 but still differ in bytes."""
    found = [FloatNoise(0.0, "")]

    def walk(a: Any, b: Any, where: str) -> bool:
        if type(a) is float and type(b) is float:
            if a != a or b != b:  # nan: the same only when both are
                return a != a and b != b
            difference = 0.0 if a == b else abs(a - b)  # inf - inf is nan, but equal infinities are the same
            share = _share(where, difference)
            if share > found[0].share:
                found[0] = FloatNoise(difference, where, share)
            return True
        if isinstance(a, dict) and isinstance(b, dict):
            return a.keys() == b.keys() and all(walk(a[k], b[k], f"{where}.{k}" if where else k) for k in sorted(a))
        if isinstance(a, list) and isinstance(b, list):
            return len(a) == len(b) and all(walk(x, y, f"{where}[{i}]") for i, (x, y) in enumerate(zip(a, b)))
        return type(a) is type(b) and a == b

    return found[0] if walk(new, old, "") else None
