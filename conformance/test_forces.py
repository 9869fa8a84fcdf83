"""Forces and torques behave as documented: exact velocity changes F·dt/m and I⁻¹·τ·dt.

A free body (the ``free_fall`` scene: damping off, gravity −10) is pushed before one step and its
velocity read after it. pybullet integrates a push exactly (measured: to ~1e-16), so the checks are
exact up to rounding: Δv = F·dt/m + g·dt from the closed form; Δω = I⁻¹·τ·dt with I the solid's
textbook inertia for the drawn mass and size, turned to the world by the body's orientation, and
τ = (posObj − COM) × F for an off-centre force. A spinning body also turns by its own gyroscopic
term, so Δω is measured against a twin: the same scene built again and stepped without the push.
Everything stays far below pybullet's ±100 clamp on velocity coordinates, except where the clamp is
the subject. The guide's own snippets are concrete cases.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import example, given, settings, strategies as st

from conformance import scenes
from conformance.bullet.deviations import NO_SHRINK, expected_failure
from conformance.bullet.physics import Push, base_state, expected_push, solid_inertia
from conformance.checks.physics_assertions import assert_close, assert_vector_close, context
from conformance.checks.profiles import check_settings
from conformance.checks.strategies import (
    force_frames,
    forces,
    free_bodies,
    lever_arms,
    scene_parameters,
    speed_gains,
    substeps,
    torques,
)

FREE_FALL = "free_fall"
GRAVITY = np.array([0.0, 0.0, -10.0])  # free_fall's SceneSpec gravity
#: A push is integrated exactly; what is left is rounding (measured ≤ 3e-16 relative).
EXACT = dict(rtol=1e-12, atol=1e-12)
#: Through a revolute joint pybullet's link frames add rounding: measured ≤ 1.5e-7 of the largest
#: joint-speed change the force could make, (|COM − hinge| + |lever|)·|F|·dt/I (500 examples).
THROUGH_JOINT = 1e-6


def measure_pushes(params, pushes, *, substeps: int = 1, steps: int = 1, setup=None, repeat: bool = False):
    """Build ``free_fall`` with ``params`` twice; push one before its first step (before every step
    if ``repeat``), step both ``steps`` times (``numSubSteps`` = ``substeps``). Returns the pushed
    run's base states (before, after step 1, …), the twin's, the body's Shape and dt."""
    states = {}
    for pushed in (True, False):
        with scenes.build(FREE_FALL, **params) as scene:
            body = scene.bindings[0].body
            if setup is not None:
                setup(scene, body)
            if substeps > 1:
                scene.p.setPhysicsEngineParameter(numSubSteps=substeps)
            trail = [base_state(scene.p, body)]
            for step in range(steps):
                if pushed and (step == 0 or repeat):
                    for push in pushes:
                        push.apply(scene.p, body)
                scene.advance(step)
                trail.append(base_state(scene.p, body))
            states[pushed] = trail
            shape, dt = scene.bindings[0].shape, scene.dt
    return states[True], states[False], shape, dt


def verify_push(params, pushes, *, expected_pushes=None, mass=None, substeps: int = 1, spin: bool = True) -> None:
    """Push with ``pushes`` and assert the velocity change one step later is what ``expected_pushes``
    (default: the same) give a body of mass ``mass`` (default: the scene's): Δv = ΣF·dt/m + g·dt,
    and (``spin``) Δω = I⁻¹·Σ(τ + r × F)·dt beyond the twin's."""
    __tracebackhide__ = True
    expected_pushes = pushes if expected_pushes is None else expected_pushes
    mass = params["mass"] if mass is None else mass
    pushed, twin, shape, dt = measure_pushes(params, pushes, substeps=substeps)
    before, after = pushed
    dv, dw = expected_push(expected_pushes, mass=mass, moments=solid_inertia(shape.kind, shape.size, mass),
                           orientation=before.orientation, dt=dt)
    where = context(FREE_FALL, params, "step 1" + (f" of {substeps} sub-steps" if substeps > 1 else ""),
                    "; ".join(p.describe() for p in pushes))
    assert_vector_close("Δv", actual=after.linear - before.linear, expected=dv + GRAVITY * dt, where=where,
                        law="ΣF·dt/m + g·dt", **EXACT)
    if spin:
        assert_vector_close("Δω", actual=after.angular - twin[1].angular, expected=dw, where=where,
                            law="I⁻¹·Σ(τ + r×F)·dt beyond the unpushed twin", **EXACT)


@check_settings(examples=8)
@given(params=free_bodies(), force=forces(20.0), lever=lever_arms(), frame=force_frames())
def test_force_changes_velocity_by_f_dt_over_m(params, force, lever, frame):
    """Quickstart Guide, applyExternalForce: "posObj […] position on the link where the force is
    applied" and "flags […] Specify the coordinate system of force/position: either WORLD_FRAME for
    Cartesian world coordinates or LINK_FRAME for local link coordinates." One step later the
    velocity has changed by F·dt/m, and an off-centre posObj has added the torque (posObj − COM) × F:
    Δω = I⁻¹·(r × F)·dt. LINK_FRAME coordinates are the link's centre-of-mass frame ("links and base
    are centered around the center of mass", getDynamicsInfo)."""
    verify_push(params, [Push(force, frame, lever)])


@check_settings(examples=6)
@given(params=free_bodies(), torque=torques(0.2), frame=force_frames())
def test_torque_changes_spin_by_inverse_inertia(params, torque, frame):
    """The guide: "External force or torque to a body can be applied using applyExternalForce and
    applyExternalTorque."; Quickstart Guide: "forceObj […] force/torque vector to be applied
    [x,y,z]. See flags for coordinate system." One step later the spin has changed by I⁻¹·τ·dt
    (τ turned to the world for LINK_FRAME) and the velocity by gravity alone."""
    verify_push(params, [Push(torque, frame, None)])


def verify_push_lifetime(params, pushes, *, repeat: bool = False) -> None:
    """Push before step 1 (and, to break the premise, ``repeat`` it before step 2) and assert that
    step 2 changes the velocity by gravity alone and the spin not at all."""
    __tracebackhide__ = True
    pushed, _, _, dt = measure_pushes(params, pushes, steps=2, repeat=repeat)
    when = "before steps 1 and 2" if repeat else "before step 1 only"
    where = context(FREE_FALL, params, "step 2", "; ".join(p.describe() for p in pushes) + f" {when}")
    assert_vector_close("Δv", actual=pushed[2].linear - pushed[1].linear, expected=GRAVITY * dt, where=where,
                        law="g·dt (the push is cleared)", **EXACT)
    assert_vector_close("Δω", actual=pushed[2].angular - pushed[1].angular, expected=np.zeros(3), where=where,
                        law="0 (the push is cleared)", **EXACT)


@check_settings(examples=5)
@given(params=free_bodies(kinds=("sphere",)), force=forces(20.0), lever=lever_arms(), torque=torques(0.2),
       frame=force_frames())
def test_push_lasts_one_step(params, force, lever, torque, frame):
    """Quickstart Guide, applyExternalForce/Torque: "After each simulation step, the external forces
    are cleared to zero." In the step after the push only gravity acts: Δv = g·dt and, for a
    sphere (which has no gyroscopic term), Δω = 0, exactly."""
    verify_push_lifetime(params, [Push(force, frame, lever), Push(torque, frame, None)])


@check_settings(examples=6)
@given(params=free_bodies(), first=forces(20.0), second=forces(20.0), levers=st.tuples(lever_arms(), lever_arms()),
       torque=torques(0.2), frames=st.tuples(force_frames(), force_frames(), force_frames()))
def test_pushes_in_one_step_add_up(params, first, second, levers, torque, frames):
    """The guide: "External force or torque to a body can be applied using applyExternalForce and
    applyExternalTorque." — called several times before one step, in any frames, the pushes add
    up: Δv = ΣF·dt/m, Δω = I⁻¹·Σ(τ + r × F)·dt."""
    verify_push(params, [Push(first, frames[0], levers[0]), Push(second, frames[1], levers[1]),
                         Push(torque, frames[2], None)])


@check_settings(examples=6)
@given(params=free_bodies(), force=forces(20.0), lever=lever_arms(), frame=force_frames(), count=substeps())
def test_push_acts_through_every_substep(params, force, lever, frame, count):
    """Quickstart Guide, setPhysicsEngineParameter: "numSubSteps int Subdivide the physics simulation
    step further by 'numSubSteps'." and "After each simulation step, the external forces are cleared
    to zero.": the push lasts the whole step, all its sub-steps, so Δv = F·dt/m + g·dt for any
    number of sub-steps. (The spin is not checked: between sub-steps the body turns, and with it
    its inertia in world axes, so Δω = I⁻¹·τ·dt holds only to O(ω·dt).)"""
    verify_push(params, [Push(force, frame, lever)], substeps=count, spin=False)


GUIDE_BALL = dict(kind="sphere", size=0.3, mass=3.0, height=1.5, orientation=(0.0, 0.0, 0.0, 1.0), spin=(0.0, 0.0, 0.0))


def _guide_damping(scene, body):
    # The guide never changes damping: put back pybullet's multibody default that free_fall removes.
    scene.p.changeDynamics(body, -1, linearDamping=0.04, angularDamping=0.04)


def verify_guide_snippet(snippet: str, damping: str, *, assumed_mass: float = 3.0) -> None:
    """Apply the guide's snippet to its ball and assert the first step's Δv and Δω, computed for a
    ball of ``assumed_mass`` (the guide's 3 kg unless a test breaks the premise)."""
    __tracebackhide__ = True
    push = Push((-2000.0, 0.0, 0.0), "WORLD_FRAME", (0.0, 0.0, 0.0) if snippet == "applyExternalForce" else None)
    pushed, _, _, dt = measure_pushes(GUIDE_BALL, [push], setup=_guide_damping if damping != "off" else None)
    before, after = pushed
    where = context(FREE_FALL, GUIDE_BALL, "step 1", push.describe(), f"damping {damping}")
    force, torque = push.in_world(before.orientation)
    moment = 0.4 * assumed_mass * GUIDE_BALL["size"] ** 2
    assert_vector_close("Δv", actual=after.linear - before.linear, expected=force * dt / assumed_mass + GRAVITY * dt,
                        where=where, law="F·dt/m + g·dt", **EXACT)
    assert_vector_close("Δω", actual=after.angular - before.angular, expected=torque * dt / moment, where=where,
                        law="τ·dt / (2/5·m·r²)", **EXACT)


@pytest.mark.parametrize("damping", ["off", "pybullet default"])
@pytest.mark.parametrize("snippet", ["applyExternalForce", "applyExternalTorque"])
def test_guide_snippets(snippet, damping):
    """The guide, "Application of Force/Torque": ``p.applyExternalForce(ball, -1, forceObj=[-2000, 0,
    0], posObj=ball_pos, flags=p.WORLD_FRAME)`` and ``p.applyExternalTorque(ball, -1, forceObj=[-2000,
    0, 0], flags=p.WORLD_FRAME)`` on its ball ("a spherical ball of radius = 0.3", ``baseMass=3``).
    From rest the first step changes the ball's velocity by exactly −2000/3/240 m/s along x (the
    force) or its spin by −2000/(0.4·3·0.3²)/240 = −77.16 rad/s about x (the torque), with
    pybullet's default damping too: damping acts on the velocity at the start of the step, zero here."""
    verify_guide_snippet(snippet, damping)


def verify_link_push(params, push: Push, *, expected_push: Push | None = None, settle: int = 5) -> None:
    """Push a single pendulum's bob (link 0) after ``settle`` frames and assert the joint speed
    changes beyond an unpushed twin's by ((posObj − hinge) × F)·axis·dt / (m·L² + 2/5·m·r²)."""
    __tracebackhide__ = True
    expected_push = push if expected_push is None else expected_push
    speeds, poses = {}, {}
    for pushed in (True, False):
        with scenes.build("pendulum", **params) as scene:
            p, body = scene.p, scene.bindings[1].body
            scene.run(settle)
            state = p.getLinkState(body, 0, computeForwardKinematics=1)
            poses[pushed] = tuple(np.array(v, dtype=np.float64) for v in (state[0], state[1], state[4], state[5]))
            if pushed:
                push.apply(p, body, 0)
            scene.advance(settle)
            speeds[pushed] = p.getJointState(body, 0)[1]
            dt = scene.dt
    com, com_orn, hinge, link_orn = poses[True]
    force, torque = expected_push.in_world(com_orn)  # LINK_FRAME = the link's centre-of-mass frame
    axis = _rotate(link_orn, (0.0, 1.0, 0.0))
    mass, length, radius = params["mass"], params["length"], params["radius"]
    moment = mass * length ** 2 + 0.4 * mass * radius ** 2
    expected = float((np.cross(com - hinge, force) + torque) @ axis) * dt / moment
    lever = np.linalg.norm(expected_push.lever) if not expected_push.is_torque else 0.0
    largest = (np.linalg.norm(com - hinge) + lever) * np.linalg.norm(force) * dt / moment
    where = context("pendulum", params, f"step {settle + 1}", push.describe() + " on link 0")
    assert_close("Δq̇", actual=speeds[True] - speeds[False], expected=expected, where=where,
                 law="((posObj − hinge) × F)·axis·dt / (m·L² + 2/5·m·r²)", rtol=0.0,
                 atol=THROUGH_JOINT * largest + 1e-12)


def _rotate(quaternion, vector) -> np.ndarray:
    from scipy.spatial.transform import Rotation

    return Rotation.from_quat(quaternion).apply(np.asarray(vector, dtype=np.float64))


@check_settings(examples=6)
@given(params=scene_parameters("pendulum").map(lambda d: {**d, "links": 1}), force=forces(20.0),
       lever=lever_arms(0.05), frame=force_frames())
def test_force_on_a_link_turns_its_joint(params, force, lever, frame):
    """Quickstart Guide, applyExternalForce: "linkIndex int link index or -1 for the base." A force
    on a pendulum's bob (link 0, revolute about y, inertial frame turned 0.5 rad) changes the joint
    speed by the torque it exerts about the hinge: ((posObj − hinge) × F)·axis·dt over the moment
    of inertia about the hinge, in WORLD_FRAME and in LINK_FRAME (the link's centre-of-mass frame)."""
    verify_link_push(params, Push(force, frame, lever))


def verify_clamped_push(params, gain, *, max_joint_velocity: float | None) -> None:
    """Push a free base at its centre with F = m·gain/dt and assert Δv = F·dt/m + g·dt."""
    __tracebackhide__ = True
    dt = 1.0 / 240.0
    force = tuple(float(c) * params["mass"] / dt for c in gain)
    push = Push(force, "WORLD_FRAME", (0.0, 0.0, 0.0))

    def setup(scene, body):
        if max_joint_velocity is not None:
            scene.p.changeDynamics(body, -1, maxJointVelocity=max_joint_velocity)

    pushed, _, _, dt = measure_pushes(params, [push], setup=setup)
    where = context(FREE_FALL, params, "step 1", push.describe(),
                    f"maxJointVelocity {'default' if max_joint_velocity is None else max_joint_velocity}")
    assert_vector_close("Δv", actual=pushed[1].linear - pushed[0].linear,
                        expected=np.asarray(gain) + GRAVITY * dt, where=where, law="F·dt/m + g·dt", **EXACT)


@check_settings(examples=4)
@given(params=free_bodies(), gain=speed_gains())
def test_push_past_100_m_per_s_with_clamp_raised(params, gain):
    """Quickstart Guide, changeDynamics: "maxJointVelocity double maximum joint velocity for a given
    joint, if it is exceeded during constraint solving, it is clamped […]". With maxJointVelocity
    raised to 1000, a push that changes a free base's velocity by more than 100 m/s is integrated
    exactly like any other: Δv = F·dt/m."""
    verify_clamped_push(params, gain, max_joint_velocity=1000.0)


@expected_failure("velocity-clamp-on-free-base")
@settings(check_settings(examples=3), phases=NO_SHRINK)
@given(params=free_bodies(), gain=speed_gains())
@example(params=dict(kind="sphere", size=0.5, mass=0.5, orientation=(0.0, 0.0, 0.0, 1.0), spin=(0.0, 0.0, 0.0)),
         gain=(40000.0 / 0.5 / 240.0, 0.0, 0.0))  # the guide's ball collision: 40 kN on 0.5 kg for one step
def test_free_base_is_not_clamped(params, gain):
    """Quickstart Guide, changeDynamics: "maxJointVelocity […] maximum joint velocity for a given
    joint, if it is exceeded during constraint solving, it is clamped to avoid crashing the
    simulation. […] Default maximum joint velocity is 100 units." A free base has no joint and, in
    the air, no constraint to solve: a push beyond 100 m/s must give Δv = F·dt/m. pybullet clamps
    every velocity coordinate of a multibody to ±100 after every step (deviation
    ``velocity-clamp-on-free-base``): the guide's ball collision flies at 100 m/s, not 333."""
    verify_clamped_push(params, gain, max_joint_velocity=None)
