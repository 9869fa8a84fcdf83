"""Ways to read many poses from pyBullet 3.2, each a ratio to the floor's own read.

pyBullet 3.2 has no call that reads the poses of several bodies: ``getBasePositionAndOrientation``
reads one body, ``getLinkStates`` the links of one body. So what can be chosen is how the per-body
call is made (keyword or positional client id, a ``functools.partial``, the kit's ``BoundClient``,
a Python loop or ``map``), and, for links, one ``getLinkStates`` per body or one ``getLinkState`` per
link. Also timed, to show where the floor's time goes: a pyBullet call that reads nothing
(``isConnected``: the price of crossing from Python to pyBullet), turning the poses into one numpy
array (what a vectorised sync adds), pyBullet's rotation matrix of a pose
(``getMatrixFromQuaternion``), and what a whole-actor sync writes per body on the backend in force
(:func:`.backend.actor_writes`): on FURY 0.12 ``vtkMatrix4x4.DeepCopy`` of its user matrix, on FURY 2
the ``actor.local`` setters (``position``; ``position`` and ``rotation``; ``components``; ``matrix``).

Every candidate reads ``bodies`` poses after an untimed ``stepSimulation()`` of its scene; the
figure is seconds per pose, the ratio is to the floor's read,
``pybullet.getBasePositionAndOrientation(b, physicsClientId=c)``, in the same rounds.
"""

from __future__ import annotations

import functools
import itertools
from dataclasses import dataclass

import numpy as np
import pybullet

from . import backend, grid
from .timing import Candidate, RatioToBaseline, race

__all__ = ["FLOOR_READ", "LINKS_PER_BODY", "ReadFigure", "measure"]

FLOOR_READ = "`getBasePositionAndOrientation(b, physicsClientId=c)`, in a loop"
#: Links per body of the chains the link reads are measured on (a robot arm has about this many).
LINKS_PER_BODY = 10


@dataclass(frozen=True)
class ReadFigure(RatioToBaseline):
    """``seconds`` per pose read the way ``name`` says; ``baseline``: the floor's read, per pose."""

    name: str
    note: str
    seconds: float
    baseline: float


def measure(bodies: int, *, repeats: int, number: int = 10) -> list[ReadFigure]:
    """Every way of reading ``bodies`` base poses, and as many link poses (``LINKS_PER_BODY`` a body)."""
    read, flatten = pybullet.getBasePositionAndOrientation, itertools.chain.from_iterable
    with grid.grid(bodies, shared=True) as scene, \
            grid.chains(max(1, bodies // LINKS_PER_BODY), LINKS_PER_BODY) as chains, \
            backend.actor_writes(bodies) as writes:
        c, ids, bound = scene.client, [b.body for b in scene.bindings], scene.p
        once = functools.partial(read, physicsClientId=c)
        orientations = [read(b, c)[1] for b in ids]
        k = chains.client
        links = {}
        for b in chains.bindings:
            if b.link >= 0:
                links.setdefault(b.body, []).append(b.link)
        pairs = [(body, link) for body, ids_ in links.items() for link in ids_]
        per_pose = {}  # name -> (note, poses read per call, fn, scene stepped before)
        per_pose[FLOOR_READ] = ("the floor's read", len(ids), lambda: [read(b, physicsClientId=c) for b in ids], scene)
        per_pose["`getBasePositionAndOrientation(b, c)`, in a loop"] = (
            "client id positional: no keyword dictionary", len(ids), lambda: [read(b, c) for b in ids], scene)
        per_pose["`map(getBasePositionAndOrientation, bodies, repeat(c))`"] = (
            "the loop in C (what `reference` does)", len(ids), lambda: list(map(read, ids, itertools.repeat(c))), scene)
        per_pose["`partial(getBasePositionAndOrientation, physicsClientId=c)` made once"] = (
            "one partial, called per body", len(ids), lambda: [once(b) for b in ids], scene)
        per_pose["`world.p.getBasePositionAndOrientation(b)`"] = (
            "the kit's BoundClient: a new partial per call", len(ids),
            lambda: [bound.getBasePositionAndOrientation(b) for b in ids], scene)
        per_pose["`map(...)` into one numpy array (`np.fromiter`)"] = (
            "what a vectorised sync pays to have the poses as an array", len(ids),
            lambda: np.fromiter(flatten(flatten(map(read, ids, itertools.repeat(c)))), np.float64, 7 * len(ids)),
            scene)
        per_pose["`isConnected(c)`, in a loop"] = (
            "a pyBullet call that reads nothing: the cost of the call itself", len(ids),
            lambda: [pybullet.isConnected(c) for b in ids], scene)
        per_pose["`getMatrixFromQuaternion(q)`, in a loop"] = (
            "a pose's rotation matrix: one per body for a VTK user matrix (FURY 2 takes the quaternion)", len(ids),
            lambda: [pybullet.getMatrixFromQuaternion(q) for q in orientations], scene)
        for name, (note, fn) in writes.items():  # the backend's own: what a whole-actor sync writes per body
            per_pose[name] = (note, bodies, fn, scene)
        per_pose["`getLinkState(b, l, computeForwardKinematics=1)`, per link"] = (
            f"links of {LINKS_PER_BODY}-link bodies, one call each", len(pairs),
            lambda: [pybullet.getLinkState(b, l, computeForwardKinematics=1, physicsClientId=k) for b, l in pairs], chains)
        per_pose["`getLinkState(b, l)`, per link"] = (
            "without forward kinematics: one step stale after a reset", len(pairs),
            lambda: [pybullet.getLinkState(b, l, physicsClientId=k) for b, l in pairs], chains)
        per_pose["`getLinkStates(b, links, computeForwardKinematics=1)`, per body"] = (
            f"all {LINKS_PER_BODY} links of a body in one call", len(pairs),
            lambda: [pybullet.getLinkStates(b, ls, computeForwardKinematics=1, physicsClientId=k)
                     for b, ls in links.items()], chains)
        candidates = [Candidate(name, fn, before=where.p.stepSimulation) for name, (_, _, fn, where) in per_pose.items()]
        best = race(candidates, repeats=repeats, number=number)
    baseline = best[FLOOR_READ] / len(ids)
    return [ReadFigure(name, note, best[name] / count, baseline) for name, (note, count, _, _) in per_pose.items()]
