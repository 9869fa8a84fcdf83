"""Collision filtering: the rules as the PyBullet Quickstart Guide states them, the filter calls a
check makes, and what a ``crossing`` run shows (no pytest here).

A run is observed the two ways that cannot be fooled by a filter (``getClosestPoints`` ignores all
filters, bullet3 #4376): the contact points ``getContactPoints(a, b)`` reports after every step, and
the trajectories. In the ``crossing`` scene nothing but a contact can change a body's motion, so a
pair that passes through follows free flight exactly and ends with its order along x swapped, and a
pair that collides keeps its order.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Iterable, Sequence

import numpy as np

from conformance.bullet.client import BoundClient

__all__ = [
    "AND_MODE",
    "OR_MODE",
    "FilterMode",
    "GroupMask",
    "Outcome",
    "PairFilter",
    "Pair",
    "describe_calls",
    "group_mask_rule",
    "observe",
    "pair_of",
]

AND_MODE, OR_MODE = 0, 1
MODE_NAMES = {AND_MODE: "AND", OR_MODE: "OR"}
#: Free flight is integrated exactly: x(n) = x0 + n·v·dt to rounding (measured ~1e-15 m).
FREE_FLIGHT_ATOL = 1e-9


def group_mask_rule(mode: int, group_a: int, mask_a: int, group_b: int, mask_b: int) -> bool:
    """Whether the Quickstart Guide says a pair collides under ``collisionFilterMode`` ``mode``:
    "Use 0 for default collision filter: (group A&maskB) AND (groupB&maskA). Use 1 to switch to the
    OR collision filter: (group A&maskB) OR (groupB&maskA)"."""
    a_in_b, b_in_a = bool(group_a & mask_b), bool(group_b & mask_a)
    return (a_in_b and b_in_a) if mode == AND_MODE else (a_in_b or b_in_a)


@dataclass(frozen=True)
class Pair:
    """The two bodies of a ``crossing`` scene and the links that carry their shapes."""

    a: int
    link_a: int
    b: int
    link_b: int


def pair_of(scene) -> Pair:
    first, second = scene.bindings[0], scene.bindings[1]
    return Pair(first.body, first.link, second.body, second.link)


@dataclass(frozen=True)
class PairFilter:
    """``setCollisionFilterPair`` for the pair before step ``step`` (0-based).

    ``swapped`` names the pair as (b, a, link_b, link_a). ``link_b`` overrides the link named for
    b (None: the link that carries b's shape), to build a rule that names the wrong link.
    """

    enable: int
    step: int = 0
    swapped: bool = False
    link_b: int | None = None

    def apply(self, p: BoundClient, pair: Pair) -> None:
        link_b = pair.link_b if self.link_b is None else self.link_b
        if self.swapped:
            p.setCollisionFilterPair(pair.b, pair.a, link_b, pair.link_a, self.enable)
        else:
            p.setCollisionFilterPair(pair.a, pair.b, pair.link_a, link_b, self.enable)

    def describe(self, pair: Pair) -> str:
        link_b = pair.link_b if self.link_b is None else self.link_b
        args = (f"b, a, {link_b}, {pair.link_a}" if self.swapped else f"a, b, {pair.link_a}, {link_b}")
        return f"setCollisionFilterPair({args}, {self.enable}) before step {self.step}"


@dataclass(frozen=True)
class GroupMask:
    """``setCollisionFilterGroupMask`` on body ``which`` ("a" or "b") before step ``step``."""

    which: str
    group: int
    mask: int
    step: int = 0

    def apply(self, p: BoundClient, pair: Pair) -> None:
        body, link = (pair.a, pair.link_a) if self.which == "a" else (pair.b, pair.link_b)
        p.setCollisionFilterGroupMask(body, link, self.group, self.mask)

    def describe(self, pair: Pair) -> str:
        link = pair.link_a if self.which == "a" else pair.link_b
        return f"setCollisionFilterGroupMask({self.which}, {link}, group={self.group}, mask={self.mask}) before step {self.step}"


@dataclass(frozen=True)
class FilterMode:
    """``setPhysicsEngineParameter(collisionFilterMode=mode)`` before step ``step``."""

    mode: int
    step: int = 0

    def apply(self, p: BoundClient, pair: Pair) -> None:
        p.setPhysicsEngineParameter(collisionFilterMode=self.mode)

    def describe(self, pair: Pair) -> str:
        return f"setPhysicsEngineParameter(collisionFilterMode={self.mode}) before step {self.step}"


@dataclass(frozen=True)
class Outcome:
    """What a crossing run showed.

    ``contact_frames`` are the frames after which ``getContactPoints(a, b)`` reported a point;
    ``crossed`` is whether a ended at larger x than b; ``free_flight_error`` is the largest distance
    of either body from its free-flight position over the run.
    """

    frames: int
    contact_frames: tuple[int, ...]
    crossed: bool
    free_flight_error: float
    final_x: tuple[float, float]

    @property
    def passed_through(self) -> bool:
        return not self.contact_frames and self.crossed and self.free_flight_error <= FREE_FLIGHT_ATOL

    @property
    def collided(self) -> bool:
        return bool(self.contact_frames) and not self.crossed

    def describe(self) -> str:
        if self.contact_frames:
            shown = ", ".join(map(str, self.contact_frames[:4])) + (" …" if len(self.contact_frames) > 4 else "")
            contacts = f"contact points after frames {shown}"
        else:
            contacts = "no contact points"
        order = "a ended past b (they passed through)" if self.crossed else "a ended before b (they did not pass)"
        return (f"{contacts}; {order} at x = ({self.final_x[0]:.4g}, {self.final_x[1]:.4g}); "
                f"largest departure from free flight {self.free_flight_error:.3g} m")


def observe(scene, frames: int, calls: Iterable[Any] = ()) -> Outcome:
    """Step a ``crossing`` scene ``frames`` times, making each filter call before its step."""
    p, pair = scene.p, pair_of(scene)
    by_step: dict[int, list] = {}
    for call in calls:
        by_step.setdefault(call.step, []).append(call)
    start = [np.array(p.getBasePositionAndOrientation(body)[0]) for body in (pair.a, pair.b)]
    velocity = [np.array(p.getBaseVelocity(body)[0]) for body in (pair.a, pair.b)]
    contacts, worst = [], 0.0
    for step in range(frames):
        for call in by_step.get(step, ()):
            call.apply(p, pair)
        scene.advance(step)
        frame = step + 1
        if p.getContactPoints(pair.a, pair.b):
            contacts.append(frame)
        for body, x0, v in zip((pair.a, pair.b), start, velocity):
            x = np.array(p.getBasePositionAndOrientation(body)[0])
            worst = max(worst, float(np.linalg.norm(x - (x0 + v * scene.dt * frame))))
    x_a = p.getBasePositionAndOrientation(pair.a)[0][0]
    x_b = p.getBasePositionAndOrientation(pair.b)[0][0]
    return Outcome(frames=frames, contact_frames=tuple(contacts), crossed=x_a > x_b,
                   free_flight_error=worst, final_x=(x_a, x_b))


def describe_calls(calls: Sequence[Any], pair: Pair) -> str:
    return "; ".join(c.describe(pair) for c in calls) or "no filter calls"
