"""Documented vs observed: every statement of the documents the physics checks rely on, measured
on the installed pybullet, as a table.

Each :class:`Statement` quotes its document, says what that means in numbers, and measures it
(in the kit's own scenes or a fresh client, always disconnected). Its verdict compares the
measurement with the deviation list (``conformance.bullet.deviations``):

* ``as documented``: pybullet does what the sentence says;
* ``deviates (listed: id)``: it does not, and the deviation is listed for this pybullet — the
  check that encodes the sentence is an expected failure;
* ``DEVIATES, NOT LISTED``: it does not, and nothing explains it (the checks fail too);
* ``as documented, but listed: id``: a listed deviation is gone in this pybullet (its strict
  expected failure turns into a failure as well) — narrow its range;
* ``not documented (measured)``: the documents are silent; the kit relies on the measured value.

``python -m conformance documented`` prints :func:`table` (``python -m conformance.checks.documented``
works as well).
"""

from __future__ import annotations

import importlib.metadata
import platform
from dataclasses import dataclass
from typing import Callable

import numpy as np

from conformance import scenes
from conformance.bullet import collisions, deviations, physics
from conformance.scenes import Shape
from conformance.scenes.crossing import Timeline

__all__ = ["STATEMENTS", "Row", "Statement", "rows", "table"]

QS = "Quickstart"
GUIDE = "FURY–pyBullet guide"
CROSSING = dict(kind="sphere", size_a=0.15, size_b=0.2, mass_a=1.0, mass_b=2.0, speed=1.5, gap=0.4,
                restitution=0.8, link=False, collide=True, seed=0)
ONE_WAY = (1, 2, 2, 4)  # a's group is in b's mask, b's group is not in a's: AND says pass, OR says collide


@dataclass(frozen=True)
class Statement:
    id: str
    document: str
    quote: str
    documented: str
    measure: Callable[[], tuple[str, bool | None]]  # (observed, agrees with the documented; None: undocumented)
    deviation: str | None = None


@dataclass(frozen=True)
class Row:
    statement: Statement
    observed: str
    agrees: bool | None
    verdict: str

    @property
    def unexpected(self) -> bool:
        return self.verdict.startswith(("DEVIATES", "as documented, but listed"))


# -- measurements ------------------------------------------------------------------------------
def _crossing(calls=(), **params) -> collisions.Outcome:
    params = {**CROSSING, **params}
    with scenes.build("crossing", **params) as scene:
        return collisions.observe(scene, Timeline(params).separated, calls)


def _said(outcome: collisions.Outcome) -> str:
    return "collide" if outcome.collided else ("pass through" if outcome.passed_through else "neither")


def _default_collision():
    outcome = _crossing()
    return f"two dynamic spheres {_said(outcome)}", outcome.collided


def _pair_filter():
    off = _crossing([collisions.PairFilter(0)])
    on = _crossing([collisions.PairFilter(0), collisions.PairFilter(1, step=1, swapped=True)])
    return (f"enable=0: {_said(off)}; then enable=1 (other argument order): {_said(on)}",
            off.passed_through and on.collided)


def _pair_overrides():
    masked = [collisions.FilterMode(0), collisions.GroupMask("a", 1, 0), collisions.GroupMask("b", 2, 0)]
    on = _crossing(masked + [collisions.PairFilter(1)])
    off = _crossing([collisions.PairFilter(0)])
    return (f"masks excluding each other + pair enable=1: {_said(on)}; default masks + pair enable=0: {_said(off)}",
            on.collided and off.passed_through)


def _filter_modes():
    results = {}
    for mode in (collisions.AND_MODE, collisions.OR_MODE):
        calls = [collisions.FilterMode(mode), collisions.GroupMask("a", *ONE_WAY[:2]), collisions.GroupMask("b", *ONE_WAY[2:])]
        results[mode] = _crossing(calls)
    return (f"one-way groups/masks {ONE_WAY}: mode 0 {_said(results[0])}, mode 1 {_said(results[1])}",
            results[0].passed_through and results[1].collided)


def _default_filter_mode():
    outcome = _crossing([collisions.GroupMask("a", *ONE_WAY[:2]), collisions.GroupMask("b", *ONE_WAY[2:])])
    return (f"one-way groups/masks {ONE_WAY} without setting the mode: {_said(outcome)} "
            f"({'AND' if outcome.passed_through else 'OR'} rule)", outcome.passed_through)


def _closest_points():
    params = {**CROSSING, "collide": False}
    with scenes.build("crossing", **params) as scene:
        pair = collisions.pair_of(scene)
        scene.run(Timeline(params).coincide)
        contacts = scene.p.getContactPoints(pair.a, pair.b)
        closest = scene.p.getClosestPoints(pair.a, pair.b, 0.0)
    return (f"disabled pair interpenetrating: getContactPoints reports {len(contacts)}, getClosestPoints "
            f"{len(closest)} point(s) (it ignores filters, bullet3 #4376)", None)


def _push(frame: str):
    """(Δv beyond g·dt in the step of the push, F·dt/m in world axes, Δv beyond g·dt in the next step)."""
    push = physics.Push((3.0, -5.0, 7.0), frame, (0.0, 0.0, 0.0))
    with scenes.build("free_fall", kind="box", size=0.3, mass=2.0) as scene:
        p, body = scene.p, scene.bindings[0].body
        before = physics.base_state(p, body)
        push.apply(p, body)
        scene.advance(0)
        after = physics.base_state(p, body)
        scene.advance(1)
        later = physics.base_state(p, body)
        force, _ = push.in_world(before.orientation)
        g = np.array([0.0, 0.0, -10.0]) * scene.dt
        return after.linear - before.linear - g, force * scene.dt / 2.0, later.linear - after.linear - g


def _force_lifetime():
    _, _, next_step = _push("WORLD_FRAME")
    error = float(np.linalg.norm(next_step))
    return f"velocity change in the step after the push beyond g·dt: {error:.1e} m/s", error < 1e-12


def _force_frames():
    errors = {}
    for frame in ("WORLD_FRAME", "LINK_FRAME"):
        dv, expected, _ = _push(frame)
        errors[frame] = float(np.linalg.norm(dv - expected))
    return ("Δv − F·dt/m with F in world axes (WORLD_FRAME) and turned by the body's centre-of-mass frame "
            f"(LINK_FRAME): {errors['WORLD_FRAME']:.1e}, {errors['LINK_FRAME']:.1e} m/s",
            max(errors.values()) < 1e-12)


def _time_step(dt: float, count: int):
    with scenes.build("free_fall", kind="sphere", size=0.2, mass=1.0) as scene:
        p, body = scene.p, scene.bindings[0].body
        p.setTimeStep(dt)
        p.setPhysicsEngineParameter(numSubSteps=count)
        z0 = physics.base_state(p, body).position[2]
        scene.run(10)
        state = physics.base_state(p, body)
    z, vz = physics.free_fall(z0, -10.0, dt, 10, count)
    return abs(state.linear[2] - vz), abs(state.position[2] - z)


def _set_time_step():
    dv, dz = _time_step(1.0 / 100.0, 1)
    return f"after 10 steps of 1/100 s: vz − g·dt·n = {dv:.1e}, z − closed form = {dz:.1e}", max(dv, dz) < 1e-12


def _sub_steps():
    dv, dz = _time_step(1.0 / 240.0, 4)
    return (f"4 sub-steps, 10 steps: vz − g·dt·n = {dv:.1e} (each step still advances dt), z − closed form "
            f"with h = dt/4 = {dz:.1e}", max(dv, dz) < 1e-12)


def _engine_defaults():
    with physics.fresh_client() as p:
        parameters = p.getPhysicsEngineParameters()
    gravity = (parameters["gravityAccelerationX"], parameters["gravityAccelerationY"], parameters["gravityAccelerationZ"])
    dt = parameters["fixedTimeStep"]
    return f"gravity {gravity}, fixedTimeStep {dt:.10g} (1/{1 / dt:.6g})", gravity == (0.0, 0.0, 0.0) and abs(dt - 1 / 240) < 1e-15


def _damping_default(maximal: bool) -> float:
    """The damping coefficient a fresh sphere shows in its first step from 2 m/s (quadratic law for
    multibodies, v·(1 − d)^dt for maximal-coordinate bodies)."""
    with physics.fresh_client() as p:
        body = p.createMultiBody(baseMass=1.0, baseCollisionShapeIndex=Shape("sphere", (0.2,)).collision_shape(p),
                                 useMaximalCoordinates=int(maximal))
        p.resetBaseVelocity(body, [2.0, 0.0, 0.0], [0.0, 0.0, 0.0])
        p.stepSimulation()
        v = p.getBaseVelocity(body)[0][0]
        dt = p.getPhysicsEngineParameters()["fixedTimeStep"]
    return 1.0 - (v / 2.0) ** (1.0 / dt) if maximal else (2.0 - v) / ((1.0 + 2.0) * 2.0 * dt)


def _multibody_damping():
    k = _damping_default(False)
    return f"measured linear damping {k:.9g} (0.04 as float32)", abs(k - 0.04) < 1e-6


def _maximal_damping():
    k = _damping_default(True)
    return f"measured linear damping {k:.9g}", abs(k - 0.04) < 1e-6


def _velocity_clamp():
    with scenes.build("free_fall", kind="sphere", size=0.5, mass=0.5, spin=(0.0, 0.0, 0.0)) as scene:
        p, body = scene.p, scene.bindings[0].body
        physics.Push((40000.0, 0.0, 0.0), "WORLD_FRAME").apply(p, body)
        scene.advance(0)
        vx = p.getBaseVelocity(body)[0][0]
        expected = 40000.0 / 0.5 * scene.dt
    return (f"the guide's ball-collision push (40 kN on 0.5 kg, one step) in the air: vx = {vx:.6g} m/s "
            f"(F·dt/m = {expected:.6g})", abs(vx - expected) < 1e-9)


def _restitution_product():
    steps, e_ball, e_ground = 100, 0.9, 0.8
    params = dict(radius=0.1, mass=1.0, height=physics.landing_height(steps), ball_restitution=e_ball,
                  ground_restitution=e_ground)
    with scenes.build("bouncing_ball", **params) as scene:
        ratio, _ = physics.bounce_ratio(scene, scene.bindings[1].body, 0.1, params["height"], 4 * steps)
    params["ground_restitution"] = 0.0
    with scenes.build("bouncing_ball", **params) as scene:
        alone, _ = physics.bounce_ratio(scene, scene.bindings[1].body, 0.1, params["height"], 4 * steps)
    return (f"e_ball 0.9, e_ground 0.8: apex/drop {ratio:.4f} vs (0.9·0.8)² = {0.72 ** 2:.4f}; e_ball 0.9 alone: "
            f"{alone:.4f} (product, bullet3 btManifoldResult.cpp)", None)


def _friction_product():
    params = dict(size=0.2, mass=1.0, speed=2.0, box_friction=0.5, ground_friction=0.6)
    with scenes.build("sliding_box", **params) as scene:
        deceleration, _ = physics.sliding_deceleration(scene, scene.bindings[1].body, scene.steps)
    return (f"μ_box 0.5, μ_ground 0.6: deceleration/g = {deceleration / 10:.4f} vs 0.5·0.6 = 0.3 "
            "(product, bullet3 btManifoldResult.cpp)", None)


STATEMENTS: tuple[Statement, ...] = (
    Statement("default-collision", f"{GUIDE}, Enabling collision",
              "By default, collision detection is enabled between different dynamic moving bodies.",
              "two dynamic bodies collide without any filter call", _default_collision),
    Statement("pair-filter", f"{QS}, setCollisionFilterPair", "enableCollision int 1 to enable collision, 0 to disable collision",
              "enable=0 lets the pair pass through, enable=1 restores contact, in either argument order", _pair_filter),
    Statement("pair-overrides-masks", f"{QS}, Enable/Disable Collisions",
              "setCollisionFilterPair will override the filter group/mask and other logic.",
              "the pair rule decides whatever the groups and masks say", _pair_overrides),
    Statement("filter-modes", f"{QS}, setPhysicsEngineParameter",
              "Use 0 for default collision filter: (group A&maskB) AND (groupB&maskA). Use 1 to switch to the OR "
              "collision filter: (group A&maskB) OR (groupB&maskA)",
              "mode 0: collide iff both directions match; mode 1: iff either does", _filter_modes),
    Statement("default-filter-mode", f"{QS}, setPhysicsEngineParameter", "Use 0 for default collision filter",
              "without setting it, the mode is 0 (AND)", _default_filter_mode,
              deviation="default-collision-filter-mode"),
    Statement("closest-points-and-filters", f"{QS}, getClosestPoints",
              "It is also possible to compute the closest points, independent from stepSimulation or "
              "performCollisionDetection.", "(silent about filters)", _closest_points),
    Statement("force-lifetime", f"{QS}, applyExternalForce/Torque",
              "After each simulation step, the external forces are cleared to zero.",
              "a push acts in one step only", _force_lifetime),
    Statement("force-frames", f"{QS}, applyExternalForce/Torque",
              "either WORLD_FRAME for Cartesian world coordinates or LINK_FRAME for local link coordinates.",
              "Δv = F·dt/m with F in world axes, or in the link's axes (its centre-of-mass frame)", _force_frames),
    Statement("set-time-step", f"{QS}, setTimeStep",
              "Each time you call 'stepSimulation' the timeStep will proceed with 'timeStep'.",
              "free fall follows semi-implicit Euler with that dt", _set_time_step),
    Statement("sub-steps", f"{QS}, setPhysicsEngineParameter",
              "Subdivide the physics simulation step further by 'numSubSteps'.",
              "a step is k sub-steps of dt/k", _sub_steps),
    Statement("engine-defaults", f"{QS}, setGravity; stepSimulation",
              "By default, there is no gravitational force enabled. […] The default timestep is 1/240 second",
              "gravity (0, 0, 0), fixedTimeStep 1/240", _engine_defaults),
    Statement("damping-default", f"{QS}, changeDynamics", "linearDamping double linear damping of the link (0.04 by default)",
              "a multibody's damping is 0.04", _multibody_damping),
    Statement("damping-default-maximal", f"{QS}, changeDynamics",
              "linearDamping double linear damping of the link (0.04 by default)",
              "a maximal-coordinate body's damping is 0.04", _maximal_damping,
              deviation="maximal-coordinates-damping-default"),
    Statement("velocity-clamp", f"{QS}, changeDynamics",
              "maximum joint velocity for a given joint, if it is exceeded during constraint solving, it is "
              "clamped […] Default maximum joint velocity is 100 units.",
              "a free base in the air (no joint, no constraint) is not clamped", _velocity_clamp,
              deviation="velocity-clamp-on-free-base"),
    Statement("restitution-combination", f"{QS}, changeDynamics", "restitution double bouncyness of contact.",
              "(silent about how two bodies' coefficients combine)", _restitution_product),
    Statement("friction-combination", f"{QS}, changeDynamics", "lateralFriction double lateral (linear) contact friction",
              "(silent about how two bodies' coefficients combine)", _friction_product),
)


def _verdict(statement: Statement, agrees: bool | None, version: str) -> str:
    listed = statement.deviation if statement.deviation and deviations.applies(statement.deviation, version) else None
    if agrees is None:
        return "not documented (measured)"
    if agrees:
        return f"as documented, but listed: `{listed}`" if listed else "as documented"
    return f"deviates (listed: `{listed}`)" if listed else "DEVIATES, NOT LISTED"


def rows(version: str | None = None) -> list[Row]:
    """Measure every statement on the installed pybullet (verdicts keyed by ``version``, default the
    installed one)."""
    version = version or deviations.installed_pybullet()
    result = []
    for statement in STATEMENTS:
        observed, agrees = statement.measure()
        result.append(Row(statement, observed, agrees, _verdict(statement, agrees, version)))
    return result


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def table() -> str:
    """The documented-vs-observed table as markdown, measured now."""
    version = deviations.installed_pybullet()
    lines = [
        f"Measured on pybullet {version} (numpy {importlib.metadata.version('numpy')}, Python "
        f"{platform.python_version()}) by `python -m conformance documented`.",
        "",
        "| # | Document | Statement | Documented | Observed | Verdict |",
        "|---|---|---|---|---|---|",
    ]
    for i, row in enumerate(rows(version), 1):
        s = row.statement
        lines.append(f"| {i} | {_cell(s.document)} | “{_cell(s.quote)}” | {_cell(s.documented)} | "
                     f"{_cell(row.observed)} | {row.verdict} |")
    listed = [d for d in deviations.DEVIATIONS if d.applies(version)]
    if listed:
        lines += ["", "Deviations listed for this pybullet (`conformance/bullet/deviations.py`), each an expected failure of "
                      "the check named:", ""]
        for d in listed:
            lines.append(f"* `{d.id}` (pybullet {d.affected}) — {d.check}. Evidence: {'; '.join(d.evidence)}.")
    return "\n".join(lines)


if __name__ == "__main__":  # pragma: no cover
    print(table())
