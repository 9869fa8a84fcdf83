"""Deliberately wrong syncs whose mistake depends on the order of calls: each passes every check that
syncs once after every step (or once after several), and ``conformance/test_sync_order.py`` must kill it.

They break the protocol's rules on order (README, "The sync protocol"): the sync draws the current
state whenever it is called, a second call without a step changes nothing, and calls may be skipped
between steps. Each is ``right_syncs.PerTargetSync`` with one step rewritten (as in ``wrong_syncs``),
so it works on both FURYs; each docstring starts with "Wrong:".
"""

from __future__ import annotations

import numpy as np

from right_syncs import PerTargetSync as Baseline  # the correct sync each mistake departs from

__all__ = ["CountsCallsAsSteps", "DeadReckoning", "StaticSetAtFrameZero"]


def _velocity(p, t):
    """pyBullet's linear velocity of a target (base: its centre of mass; link: its link frame)."""
    if t.link == -1:
        return p.getBaseVelocity(t.body)[0]
    return p.getLinkState(t.body, t.link, computeLinkVelocity=1, computeForwardKinematics=1)[6]


def _key(pos, orn) -> tuple:
    return tuple(float(c) for c in pos) + tuple(float(c) for c in orn)


class DeadReckoning(Baseline):
    """Wrong: draws "between physics ticks" for a display faster than the physics (the game loop's
    dead reckoning): once it has seen the physics move a body, a call that finds the body's pose
    unchanged since its last call means no step came in between, so it moves the body on by its
    velocity, ``pos += v·dt`` (dt read once, at start-up), once per such call. Every check that steps
    before each sync sees the exact pose; a second sync without a step draws every moving body a
    step ahead of pyBullet.

    Diagnosis: -
    """

    def __init__(self, world):
        super().__init__(world)
        self.dt = self.p.getPhysicsEngineParameters()["fixedTimeStep"]
        self.last = {}  # target name -> (pose read, position drawn, seen moving)

    def link_pose(self, t):
        pos, orn = super().link_pose(t)
        read = _key(pos, orn)
        last = self.last.get(t.name)
        if last is not None and last[0] == read:
            moving = last[2]
            drawn = last[1] + np.asarray(_velocity(self.p, t)) * self.dt if moving else last[1]
        else:
            moving, drawn = last is not None, np.asarray(pos, dtype=np.float64)
        self.last[t.name] = (read, drawn, moving)
        return drawn, orn


class CountsCallsAsSteps(Baseline):
    """Wrong: counts its calls as steps ("the kit calls me once per step") to keep a body moving between
    physics frames: it takes what a body moved between its last two new poses for one step's motion,
    and a call that finds the pose unchanged while pyBullet says the body moves for a step not yet
    drawn, so it draws the body that motion further along for every such call. Right while every call
    follows a step, or several; a second call without a step draws a moving body a step ahead (and,
    after a skipped stretch, the whole stretch ahead).

    Diagnosis: -
    """

    def __init__(self, world):
        super().__init__(world)
        self.seen = {}  # target name -> (pose read, position read, motion of its last "step", calls since)

    def link_pose(self, t):
        pos, orn = super().link_pose(t)
        pos = np.asarray(pos, dtype=np.float64)
        read = _key(pos, orn)
        seen = self.seen.get(t.name)
        if seen is None or seen[0] != read:
            motion = np.zeros(3) if seen is None else pos - seen[1]
            self.seen[t.name] = (read, pos, motion, 0)
            return pos, orn
        calls = seen[3] + 1
        self.seen[t.name] = (read, seen[1], seen[2], calls)
        if not any(_velocity(self.p, t)):
            return pos, orn
        return pos + calls * seen[2], orn


class StaticSetAtFrameZero(Baseline):
    """Wrong: decides once, at start-up, which bodies are static (mass 0: the ground, walls, a fixed
    base) and, to skip rewriting them every frame, re-places those only when teleported, which it
    recognises as a new pose without velocity (a static body never has any): a body made dynamic later
    (``changeDynamics(mass=…)``) falls with a velocity, so it stays drawn where it was. Static bodies
    teleported, and every dynamic one, are drawn right.

    Diagnosis: before-event
    """

    def __init__(self, world):
        super().__init__(world)
        self.static = {t.body for t in self.targets if t.link == -1 and self.p.getDynamicsInfo(t.body, -1)[0] == 0}
        self.placed = {}  # static target name -> the pose it was placed at

    def teleported(self, t) -> bool:
        pose = _key(*self.p.getBasePositionAndOrientation(t.body))
        if self.placed.get(t.name) == pose:
            return False
        linear, angular = self.p.getBaseVelocity(t.body)
        if t.name in self.placed and (any(linear) or any(angular)):
            return False  # moving: physics, which static bodies are spared
        self.placed[t.name] = pose
        return True

    def to_sync(self):
        return [t for t in self.targets if t.link >= 0 or t.body not in self.static or self.teleported(t)]
