"""Hypothesis strategies for the conformance checks (plural nouns, as in array-api-tests).

Orientations and events for the vertex checks come first; physics quantities for the behaviour
checks follow in their own section.
"""

from __future__ import annotations

import math

import numpy as np
from hypothesis import strategies as st

from conformance.bullet.events import JointReset, Kick, SoftKick, SoftTeleport, Teleport

__all__ = [
    "HARD_ORIENTATIONS",
    "app_events",
    "events",
    "frame_counts",
    "hard_orientations",
    "offsets",
    "orientations",
    "scene_parameters",
    "soft_events",
    "uniform_orientations",
]

# ---------------------------------------------------------------------------------------------
# Orientations and events (vertex conformance)
# ---------------------------------------------------------------------------------------------


def _quat(axis, angle) -> tuple[float, float, float, float]:
    axis = np.asarray(axis, dtype=np.float64) / np.linalg.norm(axis)
    s = math.sin(angle / 2)
    return (float(axis[0] * s), float(axis[1] * s), float(axis[2] * s), float(math.cos(angle / 2)))


def _euler(roll, pitch, yaw) -> tuple[float, float, float, float]:
    """pybullet's getQuaternionFromEuler([roll, pitch, yaw]) = Rz(yaw)·Ry(pitch)·Rx(roll), in numpy."""
    from scipy.spatial.transform import Rotation

    return tuple(float(c) for c in Rotation.from_euler("xyz", [roll, pitch, yaw]).as_quat())


_NEAR = 0.0045  # pybullet-facts.md: getEulerFromQuaternion forces roll to 0 within this of |pitch| = π/2

#: Orientations that break sloppy code: identity, half turns about each axis, pitch at and near
#: ±90° (Euler gimbal lock) with roll and yaw, and the same rotations written with negative w.
HARD_ORIENTATIONS: tuple[tuple[float, float, float, float], ...] = tuple(
    q
    for base in (
        (0.0, 0.0, 0.0, 1.0),
        _quat((1, 0, 0), math.pi),
        _quat((0, 1, 0), math.pi),
        _quat((0, 0, 1), math.pi),
        _quat((1, 1, 1), math.pi),
        _euler(0.7, math.pi / 2, -0.4),
        _euler(-0.3, -math.pi / 2, 1.1),
        _euler(0.5, math.pi / 2 - _NEAR / 2, 0.2),
        _euler(0.5, -math.pi / 2 + _NEAR * 2, -2.0),
        _euler(2.9, 0.3, -2.8),
    )
    for q in (base, tuple(-c for c in base))  # q and -q: the same rotation
)


def uniform_orientations() -> st.SearchStrategy[tuple[float, float, float, float]]:
    """Unit quaternions uniform over rotations (Shoemake's method from three uniforms), w of both signs."""

    def build(u):
        u1, u2, u3, sign = u
        a, b = math.sqrt(1 - u1), math.sqrt(u1)
        q = (a * math.sin(2 * math.pi * u2), a * math.cos(2 * math.pi * u2),
             b * math.sin(2 * math.pi * u3), b * math.cos(2 * math.pi * u3))
        return tuple(sign * c for c in q)

    unit = st.floats(0.0, 1.0, exclude_max=True, allow_subnormal=False)
    return st.tuples(unit, unit, unit, st.sampled_from([1.0, -1.0])).map(build)


def hard_orientations() -> st.SearchStrategy[tuple[float, float, float, float]]:
    return st.sampled_from(HARD_ORIENTATIONS)


def orientations() -> st.SearchStrategy[tuple[float, float, float, float]]:
    """Every orientation, the hard cases often."""
    return st.one_of(hard_orientations(), uniform_orientations())


def offsets(scale: float = 0.5) -> st.SearchStrategy[tuple[float, float, float]]:
    component = st.floats(-scale, scale, allow_nan=False, allow_subnormal=False)
    return st.tuples(component, component, component)


def frame_counts(longest: int = 60, shortest: int = 0) -> st.SearchStrategy[int]:
    """Run lengths from ``shortest`` (0: only the frame-0 sync) up to ``longest``; short runs often."""
    return st.one_of(st.sampled_from([n for n in (0, 1, 2) if n >= shortest]), st.integers(shortest, longest))


def _events_at(frames: int, soft: bool = False):
    frame = st.integers(0, max(frames, 0))
    which = st.integers(0, 1000)
    teleports = st.builds(Teleport, frame=frame, which=which, offset=offsets(), orientation=orientations())
    joint_resets = st.builds(JointReset, frame=frame, which=which, value=st.floats(-math.pi, math.pi),
                             orientation=orientations())
    kicks = st.builds(Kick, frame=frame, which=which, velocity=offsets(3.0), offset=offsets(0.05),
                      spin=offsets(20.0))
    if soft:
        return st.one_of(teleports, joint_resets, kicks, soft_events(frames))
    return st.one_of(teleports, joint_resets, kicks)


def soft_events(frames: int) -> st.SearchStrategy:
    """One teleport (moved up to 0.5 m, turned to any orientation) or kick (up to 3 m/s) of a soft body at a
    frame of 0..``frames`` (:class:`~conformance.bullet.events.SoftTeleport`, ``SoftKick``)."""
    frame = st.integers(0, max(frames, 0))
    which = st.integers(0, 1000)
    return st.one_of(st.builds(SoftTeleport, frame=frame, which=which, offset=offsets(), orientation=orientations()),
                     st.builds(SoftKick, frame=frame, which=which, velocity=offsets(3.0)))


def app_events(ticks: int, most: int = 4) -> st.SearchStrategy[list]:
    """Events for an app (:mod:`conformance.apps.perturb`): as :func:`events`, at ticks 1..``ticks``-1, so
    that each is applied before one of the app's callbacks and the last tick shows its effect; and up to
    one teleport or kick of a soft body (a no-op in an app without one)."""
    import dataclasses

    frames = max(ticks - 1, 1)
    drawn = st.tuples(events(frames, most), st.lists(soft_events(frames), max_size=1))
    return drawn.map(lambda both: sorted([dataclasses.replace(e, frame=max(e.frame, 1)) for e in both[0] + both[1]],
                                         key=lambda e: e.frame))


def events(frames: int, most: int = 4, soft: bool = False) -> st.SearchStrategy[list]:
    """Up to ``most`` teleports, joint resets and kicks at frames 0..``frames``, in frame order; with ``soft``
    (a scene with soft bodies), teleports and kicks of soft bodies among them."""
    return st.lists(_events_at(frames, soft), max_size=most).map(lambda es: sorted(es, key=lambda e: e.frame))


def scene_parameters(name: str) -> st.SearchStrategy[dict]:
    """The scene's own parameter strategy (see each scene module's ``parameters()``)."""
    from conformance import scenes

    spec = scenes.get(name)
    return spec.parameters() if spec.parameters is not None else st.just({})


# ---------------------------------------------------------------------------------------------
# Physics quantities (collision filters, forces, materials): conformance/test_{filters,forces,materials}.py
# ---------------------------------------------------------------------------------------------
# Ranges keep every check inside what its closed form assumes: speeds well under pybullet's
# 100 m/s clamp (unless a check asks for more), closing speeds that cannot step through a body,
# combined restitution above the 0.2 m/s threshold for the drops drawn. Values are plain floats,
# ints and strings, so a falsifying example reads as the call that failed.

#: The two ``flags`` of applyExternalForce/Torque, by name (the check maps them to pybullet's ints).
FORCE_FRAMES = ("WORLD_FRAME", "LINK_FRAME")


def masses(low: float = 0.1, high: float = 10.0) -> st.SearchStrategy[float]:
    """Body masses in kg."""
    return st.floats(low, high, allow_nan=False, allow_subnormal=False)


def sizes(low: float = 0.05, high: float = 0.5) -> st.SearchStrategy[float]:
    """Characteristic lengths in m (half extent, radius)."""
    return st.floats(low, high, allow_nan=False, allow_subnormal=False)


def shape_kinds(kinds=("box", "sphere", "cylinder")) -> st.SearchStrategy[str]:
    return st.sampled_from(tuple(kinds))


def _vectors(scale: float) -> st.SearchStrategy[tuple[float, float, float]]:
    component = st.floats(-scale, scale, allow_nan=False, allow_subnormal=False)
    return st.tuples(component, component, component)


def forces(scale: float = 50.0) -> st.SearchStrategy[tuple[float, float, float]]:
    """Force vectors in N, each component in [-scale, scale]."""
    return _vectors(scale)


def torques(scale: float = 2.0) -> st.SearchStrategy[tuple[float, float, float]]:
    """Torque vectors in N·m."""
    return _vectors(scale)


def lever_arms(scale: float = 0.2) -> st.SearchStrategy[tuple[float, float, float]]:
    """``posObj`` minus the centre of mass, in m: often exactly zero (a push at the centre)."""
    return st.one_of(st.just((0.0, 0.0, 0.0)), _vectors(scale))


def spins(scale: float = 5.0, least: float = 0.0) -> st.SearchStrategy[tuple[float, float, float]]:
    """Angular velocities in rad/s, each component in [-scale, scale], of norm at least ``least``."""
    return _vectors(scale).filter(lambda v: math.hypot(*v) >= least)


def velocities(scale: float = 5.0, least: float = 0.0) -> st.SearchStrategy[tuple[float, float, float]]:
    """Linear velocities in m/s, each component in [-scale, scale], of norm at least ``least``."""
    return _vectors(scale).filter(lambda v: math.hypot(*v) >= least)


def force_frames() -> st.SearchStrategy[str]:
    return st.sampled_from(FORCE_FRAMES)


def timesteps() -> st.SearchStrategy[float]:
    """``setTimeStep`` values in s: the usual rates and anything from 1/2000 to 1/50."""
    usual = st.sampled_from([1 / 60, 1 / 120, 1 / 240, 1 / 500, 1 / 1000])
    return st.one_of(usual, st.floats(1 / 2000, 1 / 50, allow_nan=False, allow_subnormal=False))


def substeps(most: int = 8) -> st.SearchStrategy[int]:
    """``numSubSteps`` values (1 = no subdivision)."""
    return st.integers(1, most)


def damping_factors(high: float = 0.5) -> st.SearchStrategy[float]:
    """``linearDamping``/``angularDamping`` values."""
    return st.floats(0.0, high, allow_nan=False, allow_subnormal=False)


def restitutions(low: float = 0.5, high: float = 0.95) -> st.SearchStrategy[float]:
    return st.floats(low, high, allow_nan=False, allow_subnormal=False)


def landing_steps(low: int = 60, high: int = 140) -> st.SearchStrategy[int]:
    """Drops that reach the plate exactly at the end of step n: the height is the integrator's own
    free-fall distance g·dt²·n(n+1)/2, so the impact is not split across a step (see
    ``conformance.bullet.physics.landing_height``). 60..140 steps at 1/240 s are drops of 0.3..1.7 m."""
    return st.integers(low, high)


def bitmasks(bits: int = 4) -> st.SearchStrategy[int]:
    """Collision filter groups and masks: ``bits``-bit values, 0 (nothing) and -1 (every bit)."""
    return st.one_of(st.integers(0, 2**bits - 1), st.sampled_from([0, -1]))


def filter_modes() -> st.SearchStrategy[int]:
    """``collisionFilterMode``: 0 = AND, 1 = OR."""
    return st.sampled_from([0, 1])


def group_masks(bits: int = 4) -> st.SearchStrategy[tuple[int, int, int, int]]:
    """(group_a, mask_a, group_b, mask_b) for ``setCollisionFilterGroupMask`` on a pair."""
    return st.tuples(bitmasks(bits), bitmasks(bits), bitmasks(bits), bitmasks(bits))


def one_way_group_masks(bits: int = 4) -> st.SearchStrategy[tuple[int, int, int, int]]:
    """Group/mask pairs on which the AND and OR rules disagree: exactly one body's group is in the
    other's mask. Built directly, so every example tells the two rules apart."""
    full = 2**bits - 1

    def build(draw_):
        group, mask_bits, other_group, other_mask, swap = draw_
        mask = mask_bits | (group & -group)  # shares group's lowest bit
        other_mask &= ~other_group & full      # shares no bit with other_group
        first = (group, other_mask, other_group, mask)  # a's group in b's mask; b's group not in a's
        return (first[2], first[3], first[0], first[1]) if swap else first

    return st.tuples(st.integers(1, full), st.integers(0, full), st.integers(0, full), st.integers(0, full),
                     st.booleans()).map(build)


def toggle_schedules(last_step: int, most: int = 4) -> st.SearchStrategy[list[tuple[int, int, bool]]]:
    """Up to ``most`` ``setCollisionFilterPair`` calls as (step, enable, swapped), in step order,
    all before step ``last_step``; ``swapped`` names the pair in the other argument order."""
    call = st.tuples(st.integers(0, max(last_step, 0)), st.sampled_from([0, 1]), st.booleans())
    return st.lists(call, min_size=1, max_size=most).map(lambda calls: sorted(calls, key=lambda c: c[0]))


def free_bodies(kinds=("box", "sphere", "cylinder")) -> st.SearchStrategy[dict]:
    """Parameters of the ``free_fall`` scene: any shape kind, size, mass, orientation and spin.
    Sizes from 0.1 m and masses from 0.5 kg keep the pushes drawn here under ~30 rad/s and ~1 m/s,
    far from pybullet's ±100 clamp on every velocity coordinate."""
    return st.fixed_dictionaries({
        "kind": shape_kinds(kinds),
        "size": sizes(0.1, 0.5),
        "mass": masses(0.5, 10.0),
        "orientation": orientations(),
        "spin": spins(5.0),
    })


def speed_gains(low: float = 105.0, high: float = 400.0) -> st.SearchStrategy[tuple[float, float, float]]:
    """Velocity changes in m/s with at least one component beyond ±``low`` (past the 100 m/s clamp)."""
    big = st.floats(low, high, allow_nan=False).flatmap(lambda s: st.sampled_from([s, -s]))
    small = st.floats(-low / 2, low / 2, allow_nan=False, allow_subnormal=False)
    return st.tuples(big, small, small, st.integers(0, 2)).map(
        lambda t: tuple(t[(i - t[3]) % 3] for i in range(3)))


def crossing_parameters(**fixed) -> st.SearchStrategy[dict]:
    """Parameters of the ``crossing`` scene with ``fixed`` ones (e.g. ``collide=True``) overriding."""
    return scene_parameters("crossing").map(lambda d: {**d, **fixed})


__all__ += [
    "FORCE_FRAMES", "bitmasks", "crossing_parameters", "damping_factors", "filter_modes", "force_frames", "free_bodies",
    "forces", "group_masks", "landing_steps", "lever_arms", "masses", "one_way_group_masks",
    "restitutions", "shape_kinds", "sizes", "speed_gains", "spins", "substeps", "timesteps", "toggle_schedules", "torques",
    "velocities",
]
