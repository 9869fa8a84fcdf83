"""Closed forms and measurements for the physics checks: velocity changes, free fall, damping,
bounces and sliding (no pytest here).

Everything is read through the scene's bound client. Expected values come from the parameters a
check drew (mass, size, force…) and textbook formulas, never from pybullet's own bookkeeping of
the same quantity, so a wrong mass or inertia in pybullet would show.

Measured on pybullet 3.2.7 (see ``docs/physics.md``): a push changes a free base's velocity by
F·dt/m and its spin by I⁻¹·τ·dt to ~1e-16; free fall matches the semi-implicit Euler closed form to
~1e-14; multibody damping is exactly Δv = −k·(1 + |v|)·v·dt per step.
"""

from __future__ import annotations

import contextlib
import math
from dataclasses import dataclass
from typing import Iterator, Sequence

import numpy as np
import pybullet
from scipy.spatial.transform import Rotation

from conformance.bullet.client import BoundClient

__all__ = [
    "BaseState",
    "Push",
    "base_state",
    "bounce_ratio",
    "damped_step",
    "expected_push",
    "fresh_client",
    "free_fall",
    "landing_height",
    "sliding_deceleration",
    "solid_inertia",
    "world_inverse_inertia",
]

FRAMES = {"WORLD_FRAME": pybullet.WORLD_FRAME, "LINK_FRAME": pybullet.LINK_FRAME}


# -- bodies ------------------------------------------------------------------------------------
def solid_inertia(kind: str, size: Sequence[float], mass: float) -> np.ndarray:
    """Principal moments of a solid box (half extents), sphere (radius) or cylinder (radius,
    height along z), in kg·m²."""
    if kind == "box":
        hx, hy, hz = size
        return mass / 3.0 * np.array([hy * hy + hz * hz, hx * hx + hz * hz, hx * hx + hy * hy])
    if kind == "sphere":
        return np.full(3, 0.4 * mass * size[0] ** 2)
    radius, height = size
    side = mass * (3.0 * radius * radius + height * height) / 12.0
    return np.array([side, side, 0.5 * mass * radius * radius])


def world_inverse_inertia(orientation, moments) -> np.ndarray:
    """I⁻¹ in world axes for a body whose principal axes are turned by ``orientation`` (x, y, z, w)."""
    r = Rotation.from_quat(orientation).as_matrix()
    return r @ np.diag(1.0 / np.asarray(moments, dtype=np.float64)) @ r.T


@dataclass(frozen=True)
class BaseState:
    """A base's centre-of-mass pose and velocities (world frame)."""

    position: np.ndarray
    orientation: np.ndarray
    linear: np.ndarray
    angular: np.ndarray


def base_state(p: BoundClient, body: int) -> BaseState:
    position, orientation = p.getBasePositionAndOrientation(body)
    linear, angular = p.getBaseVelocity(body)
    return BaseState(*(np.array(v, dtype=np.float64) for v in (position, orientation, linear, angular)))


# -- pushes ------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Push:
    """One ``applyExternalForce`` (with ``lever``) or ``applyExternalTorque`` (``lever`` None).

    ``lever`` is posObj relative to the centre of mass: added to the COM's world position for
    WORLD_FRAME (as the guide passes ``posObj=ball_pos``), given as is for LINK_FRAME, whose
    coordinates are the link's centre-of-mass frame (pybullet-facts.md, "External force").
    """

    vector: tuple[float, float, float]
    frame: str = "WORLD_FRAME"
    lever: tuple[float, float, float] | None = (0.0, 0.0, 0.0)

    @property
    def is_torque(self) -> bool:
        return self.lever is None

    def apply(self, p: BoundClient, body: int, link: int = -1) -> None:
        flags = FRAMES[self.frame]
        if self.is_torque:
            p.applyExternalTorque(body, link, list(self.vector), flags=flags)
            return
        if self.frame == "WORLD_FRAME":
            centre = (p.getBasePositionAndOrientation(body)[0] if link == -1
                      else p.getLinkState(body, link, computeForwardKinematics=1)[0])
            position = [c + o for c, o in zip(centre, self.lever)]
        else:
            position = list(self.lever)
        p.applyExternalForce(body, link, list(self.vector), position, flags=flags)

    def describe(self) -> str:
        vec = "(" + ", ".join(f"{c:.6g}" for c in self.vector) + ")"
        if self.is_torque:
            return f"applyExternalTorque(forceObj={vec}, {self.frame})"
        lever = "(" + ", ".join(f"{c:.4g}" for c in self.lever) + ")"
        where = f"COM+{lever}" if self.frame == "WORLD_FRAME" else lever
        return f"applyExternalForce(forceObj={vec}, posObj={where}, {self.frame})"

    def in_world(self, orientation) -> tuple[np.ndarray, np.ndarray]:
        """(force, torque about the COM) in world axes, for a body at ``orientation``."""
        turn = Rotation.from_quat(orientation) if self.frame == "LINK_FRAME" else Rotation.identity()
        vector = turn.apply(np.asarray(self.vector, dtype=np.float64))
        if self.is_torque:
            return np.zeros(3), vector
        return vector, np.cross(turn.apply(np.asarray(self.lever, dtype=np.float64)), vector)


def expected_push(pushes: Sequence[Push], *, mass: float, moments, orientation, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """(Δv, Δω) the pushes give a free base in one step of ``dt``: F·dt/m and I⁻¹·τ·dt, summed."""
    force, torque = np.zeros(3), np.zeros(3)
    for push in pushes:
        f, t = push.in_world(orientation)
        force, torque = force + f, torque + t
    return force * dt / mass, world_inverse_inertia(orientation, moments) @ torque * dt


# -- gravity, time step, damping ---------------------------------------------------------------
def substeps_taken(dt: float, substeps: int, steps: int) -> int:
    """How many sub-steps of h = dt/substeps ``steps`` calls of stepSimulation take in all. Usually
    steps·substeps; but Bullet (btDiscreteDynamicsWorld::stepSimulation) adds dt to a clock, takes
    int(clock / h) sub-steps, capped at ``substeps``, and keeps the rest: for some dt the division
    falls just short and a sub-step is lost (measured: 10 of 1,200 random dt in 1–20 ms with 2–5
    sub-steps, every one matched by this arithmetic in double precision, pybullet's own)."""
    h, clock, taken = dt / substeps, 0.0, 0
    for _ in range(steps):
        clock += dt
        count = 0
        if clock >= h:
            count = int(clock / h)
            clock -= count * h
        taken += min(count, substeps)
    return taken


def free_fall(z0: float, g: float, dt: float, steps: int, substeps: int = 1) -> tuple[float, float]:
    """(z, vz) after ``steps`` calls of stepSimulation under semi-implicit Euler (v += g·h, then
    x += v·h) with ``substeps`` sub-steps h = dt/substeps each: vz = g·h·m,
    z = z0 + g·h²·m(m+1)/2 with m the sub-steps taken (n·substeps, bar Bullet's lost ones:
    :func:`substeps_taken`)."""
    h = dt / substeps
    m = steps * substeps if substeps == 1 else substeps_taken(dt, substeps, steps)
    return z0 + g * h * h * m * (m + 1) / 2.0, g * h * m


def damped_step(velocity, k: float, dt: float, acceleration=(0.0, 0.0, 0.0)) -> np.ndarray:
    """A multibody's velocity after one step: v + (a − k·(1 + |v|)·v)·dt, damping evaluated at the
    step's start (bullet3 btMultiBody.cpp: DAMPING_K1 = DAMPING_K2 = m_linearDamping)."""
    v = np.asarray(velocity, dtype=np.float64)
    return v + (np.asarray(acceleration, dtype=np.float64) - k * (1.0 + np.linalg.norm(v)) * v) * dt


# -- materials ---------------------------------------------------------------------------------
def landing_height(steps: int, g: float = 10.0, dt: float = 1.0 / 240.0) -> float:
    """The drop after which a body released at rest has fallen exactly that far after ``steps``
    steps: g·dt²·n(n+1)/2 (semi-implicit Euler)."""
    return g * dt * dt * steps * (steps + 1) / 2.0


def bounce_ratio(scene, ball: int, radius: float, drop: float, steps: int) -> tuple[float, int]:
    """(apex of the first rebound / drop height, frame of the impact) in a ``bouncing_ball`` run
    of at most ``steps`` frames; the apex is of the ball's lowest point above the plate (z = 0).
    The impact is the first frame at which the ball falls slower than the frame before (in free
    fall it only ever falls faster); a ball that does not rebound has an apex of 0."""
    p = scene.p
    impact, apex, rising, previous = None, 0.0, False, math.inf
    for step in range(steps):
        scene.advance(step)
        z = p.getBasePositionAndOrientation(ball)[0][2] - radius
        vz = p.getBaseVelocity(ball)[0][2]
        if impact is None:
            if vz <= previous:
                previous = vz
                continue
            impact = step + 1
        apex = max(apex, z)
        if vz > 0:
            rising = True
        elif rising:
            break
    if impact is None:
        return math.nan, -1
    return apex / drop, impact


def sliding_deceleration(scene, box: int, steps: int, slowest: float = 0.2) -> tuple[float, int]:
    """(mean deceleration along x from launch until the box has lost (1 − ``slowest``) of its
    speed, frames averaged). The mean from launch rides through the first frames, in which the
    contact is found, and through the rocking of small boxes, which single frames do not."""
    p = scene.p
    v0 = p.getBaseVelocity(box)[0][0]
    last, v_last = 0, v0
    for step in range(steps):
        scene.advance(step)
        v = p.getBaseVelocity(box)[0][0]
        if v <= slowest * v0:
            break
        last, v_last = step + 1, v
    if last == 0:
        return math.nan, 0
    return (v0 - v_last) / (last * scene.dt), last


# -- engine defaults ---------------------------------------------------------------------------
@contextlib.contextmanager
def fresh_client() -> Iterator[BoundClient]:
    """A DIRECT client exactly as ``connect`` leaves it (no gravity or time step set), for reading
    pybullet's defaults; always disconnected."""
    client = pybullet.connect(pybullet.DIRECT)
    try:
        yield BoundClient(client)
    finally:
        if pybullet.isConnected(physicsClientId=client):
            pybullet.disconnect(physicsClientId=client)
