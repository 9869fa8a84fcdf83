"""Which known mistake a wrong drawing is: the catalogue of the usual sync mistakes, as poses.

When a target is drawn out of tolerance, its drawn vertices are tried against the pose each usual
mistake would have drawn them at (:data:`MISTAKES`); when one pose holds every vertex within twice
the tolerance (float32 storage rounds the drawing and the kit's own arithmetic rounds the candidate)
the failure says so in one line, ``diagnosis: …``. A pose within :data:`DISTINCT` allowances of
pyBullet's is never offered (the drawing could be nearer the truth than the mistake), and a drawing no
pose holds gets no diagnosis: the catalogue names a mistake only when it reproduces the drawing. A
target whose vertices are right and whose stored normals are not is tried the same way against the
normals' mistakes (:data:`NORMAL_MISTAKES`), and a change never announced is named as such.

The poses pyBullet had earlier (the previous step, before a teleport or a joint reset) are the ones
the run kept as it went (:class:`conformance.sync.runner.Run`'s ``previous`` and ``before_events``): one
read of every target's pose per frame, where replaying the physics up to each failing frame made a
wrong sync's survey of a long scene cost a run per failing frame.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import pybullet

from conformance.bullet import poses, truth
from conformance.judge.ties import UNDECIDED  # a later frame tells each pair apart (undecided)

__all__ = ["EULER_ORDERS", "MISTAKES", "NORMAL_MISTAKES", "SOFT_WORDS", "UNDECIDED", "Drawn", "diagnose", "diagnose_frame",
           "diagnose_normals", "diagnose_problems", "drawn_now", "explain", "explain_failures", "explain_frame",
           "explain_normals", "late_or_once", "name_of", "soft_drawn_as_rigid", "soft_names", "unannounced"]

#: name → what it means (printed after "diagnosis: ")
MISTAKES = {
    "previous-step": "drawn exactly at pyBullet's pose of the previous step (frame {frame}): sync after "
                     "p.stepSimulation(), and read links with getLinkState(..., computeForwardKinematics=1)",
    "before-event": "drawn at the pose before the {event} of frame {frame}: the sync did not draw the move (it skips "
                    "bodies it believes at rest or static, caches poses, or draws the previous step); read every pose "
                    "at every call, after p.stepSimulation()",
    "com-frame": "drawn at the centre-of-mass frame ({call}) instead of the link frame: undo the inertial offset, "
                 "getDynamicsInfo(body, -1)[3:5] for a base, or read links with getLinkState(...)[4:6]",
    "conjugate": "drawn with the inverse rotation (the conjugate quaternion, or the rotation matrix transposed): "
                 "a row vector `v @ R` where `R @ v` was meant, or a matrix written by rows into a column-major one",
    "wxyz": "drawn with the quaternion reordered to (w, x, y, z) and handed to something that takes pyBullet's "
            "(x, y, z, w): pass pyBullet's quaternion as it is",
    "scalar-first": "drawn with pyBullet's (x, y, z, w) quaternion read as (w, x, y, z) (transforms3d, Eigen, "
                    "scipy's scalar_first=True): read it as (x, y, z, w)",
    "euler-order": "drawn with pyBullet's Euler angles composed in another order than pyBullet's ({order}; "
                   "getEulerFromQuaternion's angles mean R = Rz(yaw)·Ry(pitch)·Rx(roll), turns about fixed x, y, z): "
                   "set the rotation from the quaternion",
    "never-moved": "drawn where it was built: this target's vertices (or its actor's transform) were never updated "
                   "(a loop that skips it, a condition that leaves it out, or vertex ranges that miss it)",
    "translation-only": "moved but never turned: the position is pyBullet's, the rotation the one it was built with",
    "rotation-only": "turned but never moved: the rotation is pyBullet's, the position the one it was built with",
    "other-target": "drawn at the pose of {other}: the vertex range or the actor was paired with the wrong body or link",
    "node-order": "each vertex is drawn at one of the soft body's nodes, but not at the node it follows: the nodes "
                  "were copied in another order than the faces index them; copy getMeshData(body, -1, "
                  "flags=p.MESH_DATA_SIMULATION_MESH)[1][t.nodes] in order",
}

_COPY = "copy getMeshData(body, -1, flags=p.MESH_DATA_SIMULATION_MESH)[1] after p.stepSimulation(), at every call"
#: The words of a mistake found on a soft body, whose drawing follows nodes, not a pose.
SOFT_WORDS = {
    "previous-step": "drawn exactly at the soft body's nodes of the previous step (frame {frame}): " + _COPY,
    "never-moved": "drawn at the soft body's nodes as built: its vertices were never copied again; " + _COPY,
    "late-or-once": "drawn at the soft body's nodes of the previous step (frame {frame}), which are the nodes as "
                    "built: copied one step late or only once, which the next frames tell apart; " + _COPY,
    "part-copied": "only {copied} of the soft body's {count} vertices follow its nodes; the others are drawn where "
                   "they were built or a step late: the copy stops short (a slice, a loop bound, another mesh's count); "
                   + _COPY,
    "float16": "drawn at the soft body's nodes rounded to float16 (half precision: 11 bits, a millimetre at two "
               "metres): keep the vertices in float32 or float64; " + _COPY,
    "soft-posed": "drawn at the soft body's nodes moved again by the body's pose (getBasePositionAndOrientation, as "
                  "the rigid bodies' code poses their actors, given to the soft body's actor too): the nodes are "
                  "already in the world's frame; leave a soft body's actor at the identity pose and " + _COPY,
    "rigid-or-posed": "{name} is a soft body drawn at its pose (getBasePositionAndOrientation) applied to its nodes "
                      "as they are now, which are also its vertices as built: posed as if rigid, or its nodes moved "
                      "again by that pose, which a frame where it has changed shape tells apart; a soft body's "
                      "vertices are its nodes as they are: " + _COPY,
    "visual-mesh": "drawn at the soft body's visual mesh (getMeshData without MESH_DATA_SIMULATION_MESH: one vertex "
                   "per corner of each face, {corners} of them, not the {count} nodes in order): " + _COPY,
    "every-node": "vertex k is drawn at node k, the first {drawn} of the body's {count} nodes: this soft body is "
                  "volumetric (tetrahedra) and only its {drawn} boundary nodes are drawn, vertex k at node "
                  "Target.nodes[k]; the nodes inside are never drawn: " + _COPY,
    # A sync written before soft bodies, which hands every target to its pose code: kept under the
    # JUnit message's share of a diagnosis (conformance.reports.junit), so that -m "not soft" stays in it.
    "drawn-as-rigid": "{name} is a soft body (Target.nodes is not None) and the sync {how}: its vertices must follow "
                      "the nodes p.getMeshData(body, -1, flags=p.MESH_DATA_SIMULATION_MESH)[1] (README, The sync "
                      "protocol). No soft bodies in your program? -m \"not soft\" leaves soft scenes out",
}
#: How a sync drew a soft body as a rigid one, in the words of ``SOFT_WORDS["drawn-as-rigid"]``.
_AS_RIGID = {"posed": "posed it as if rigid", "untouched": "never wrote its vertices"}

#: name → what it means, for a target whose vertices are right and whose stored normals are not
NORMAL_MISTAKES = {
    "stale-normals": "the normals buffer is as built, never turned: the sync rewrote the positions but not the "
                     "normals; turn the normals by the same rotation (or move the actor by its matrix, which turns both)",
    "normals-previous-step": "the normals are turned as the body was at the previous step (frame {frame}) while "
                             "the positions are current: turn both from the pose read after p.stepSimulation()",
    "stale-or-late-normals": "the normals buffer is as built, never turned, or turned a step late: the body's rotation "
                             "at the previous step (frame {frame}) is still the one it was built with, so the two "
                             "cannot be told apart yet; turn the normals with the positions, from the pose read after "
                             "p.stepSimulation()",
    "normals-twice": "the normals are turned twice: the sync turned the normals in the buffer and the actor's matrix "
                     "turns them again; turn them in one place only",
    "normals-inverse": "the normals are turned by the inverse rotation (the conjugate quaternion, or the matrix "
                       "transposed) while the positions are turned right: use the positions' rotation for both",
    "normals-dropped": "the actor stores no normals any more (its geometry was replaced without them), so it is lit "
                       "flat or not at all: keep the normals array and turn it with the positions",
    "unannounced": "a change never announced to the renderer: the sync wrote the vertex data but did not mark it "
                   "modified ({announce}), so a live window keeps drawing the old vertices; announce every buffer "
                   "it changes, each time it changes it",
}


#: A mistake is named only when its pose is this many allowances from pyBullet's, so that a drawing
#: within the allowance of the mistake is nearer the mistake than the truth (a drawing halfway between
#: the two, e.g. a rotation by half the angle, is never named).
DISTINCT = 2


@dataclass(frozen=True)
class Drawn:
    """One failing target's drawn vertices ``(n, 3)`` (world) at ``frame``, and pyBullet's poses of every
    target then (:class:`_Physics`), kept when the failure was found so that its diagnosis can be made
    later (survey mode reports after the run moved on)."""

    index: int
    frame: int
    vertices: np.ndarray
    physics: "_Physics"


@dataclass(frozen=True)
class _Physics:
    """pyBullet's link-frame poses of every target at the failing frame (``now``), the one before
    (``previous``, None at frame 0) and just before each event so far (``before_events``), and the
    centre-of-mass poses at the failing frame (``com``)."""

    now: tuple[np.ndarray, np.ndarray]
    previous: tuple[np.ndarray, np.ndarray] | None
    before_events: list[tuple[Any, tuple[np.ndarray, np.ndarray]]]
    com: tuple[np.ndarray, np.ndarray]
    #: Each soft target's body's nodes now and at the previous step (None at frame 0), by target index.
    nodes: dict[int, np.ndarray]
    previous_nodes: dict[int, np.ndarray] | None
    #: The soft targets whose actor's vertex data the sync has never written (nor announced) so far, by index.
    untouched: frozenset[int] = frozenset()
    #: Each soft target's poses as a sync written for rigid bodies reads them: its base's centre of mass
    #: (``getBasePositionAndOrientation``) and the link frame made from it with ``getDynamicsInfo(body, -1)[3:5]``.
    rigid_poses: dict[int, list[tuple[np.ndarray, np.ndarray]]] | None = None


def _physics(run) -> _Physics:
    """pyBullet's poses of every target of ``run`` (a :class:`conformance.sync.runner.Run`) now, and the
    earlier ones the run kept as it went."""
    p = run.drawing.world.p
    items = [(u.body, u.link) for u in run.drawing.targets]
    com_pos, com_orn = np.empty((len(items), 3)), np.empty((len(items), 4))
    for i, (body, link) in enumerate(items):
        if link < 0:
            pos, orn = pybullet.getBasePositionAndOrientation(body, physicsClientId=p.client)
        else:
            pos, orn = pybullet.getLinkState(body, link, computeForwardKinematics=1, physicsClientId=p.client)[:2]
        com_pos[i], com_orn[i] = pos, orn
    soft = [i for i, t in enumerate(run.drawing.targets) if t.nodes is not None]
    nodes = {i: truth.nodes(p, run.drawing.targets[i].body) for i in soft}
    names = {id(actor): name for name, actor in run.drawing.actors.items()}
    wrote = getattr(run, "wrote", None)
    untouched = frozenset(i for i in soft if wrote is not None and names.get(id(run.drawing.targets[i].actor)) not in wrote)
    rigid = {i: _rigid_poses(p, run.drawing.targets[i].body, com_pos[i], com_orn[i]) for i in soft}
    return _Physics(run.poses(), run.previous, list(run.before_events), (com_pos, com_orn), nodes, run.previous_nodes,
                    untouched, rigid)


def _rigid_poses(p, body: int, com_pos, com_orn) -> list[tuple[np.ndarray, np.ndarray]]:
    """(position, rotation matrix) of soft body ``body`` as a rigid body's pose code reads it: its centre of
    mass, and the link frame the README's example makes of it (pyBullet's inertial frame of a soft body is not
    a rotation one can rely on: one that is no rotation at all is left out)."""
    com_r = poses.matrices(com_orn)
    found = [(np.asarray(com_pos, dtype=np.float64), com_r)]
    inertial_pos, inertial_orn = pybullet.getDynamicsInfo(body, -1, physicsClientId=p.client)[3:5]
    inertial_orn = np.asarray(inertial_orn, dtype=np.float64)
    if np.all(np.isfinite(inertial_orn)) and np.linalg.norm(inertial_orn) > 0.5:
        r = com_r @ poses.matrices(inertial_orn).T
        found.append((np.asarray(com_pos, dtype=np.float64) - r @ np.asarray(inertial_pos, dtype=np.float64), r))
    return found


def drawn_now(run, names, frame: int) -> dict[str, Drawn]:
    """What the targets named ``names`` of ``run`` are drawn as now, with pyBullet's poses read once."""
    from conformance import backends

    physics = None
    found = {}
    for i, t in enumerate(run.drawing.targets):
        if t.name in names:
            physics = physics or _physics(run)
            vertices = np.array(backends.world_vertices(t.actor)[t.start:t.stop], dtype=np.float64)
            found[t.name] = Drawn(i, frame, vertices, physics)
    return found


#: Euler compositions renderers make of (roll, pitch, yaw): scipy intrinsic order and the angles' order
EULER_ORDERS = {
    "VTK's SetOrientation(x, y, z) turns about z, then the turned x, then the turned y: Rz·Rx·Ry": ("ZXY", (2, 0, 1)),
    "one axis at a time, x, then y, then z about the turned axes (VTK's RotateX/Y/Z), or z, y, x about the "
    "world axes (FURY 2's rotate): Rx·Ry·Rz": ("XYZ", (0, 1, 2)),
}


def _candidates(run, physics: _Physics, i: int, frame: int):
    """``(name, words, position, matrix)`` of every mistake's pose for target ``i`` at ``frame``."""
    t = run.drawing.targets[i]
    p, q = physics.now[0][i], physics.now[1][i]
    built_p, built_q = np.asarray(t.position, dtype=np.float64), np.asarray(t.orientation, dtype=np.float64)
    r = poses.matrices(q)
    # An event of this very frame first: the pose before it is also the previous step's, and "missed the
    # move" covers both; then the previous step; then the poses before earlier events, latest first.
    latest = [(e, b) for e, b in physics.before_events if e.frame == frame]
    earlier = [(e, b) for e, b in physics.before_events if e.frame < frame]
    for event, before in latest:
        yield "before-event", {"event": _event_name(event), "frame": event.frame}, *_pose(before, i)
    if physics.previous is not None:
        yield "previous-step", {"frame": frame - 1}, *_pose(physics.previous, i)
    for event, before in reversed(earlier):
        yield "before-event", {"event": _event_name(event), "frame": event.frame}, *_pose(before, i)
    com_call = "getBasePositionAndOrientation" if t.link < 0 else "getLinkState(...)[0:2]"
    yield "com-frame", {"call": com_call}, physics.com[0][i], poses.matrices(physics.com[1][i])
    yield "conjugate", {}, p, r.T
    yield "wxyz", {}, p, poses.matrices(np.roll(q, 1))
    yield "scalar-first", {}, p, poses.matrices(np.roll(q, -1))
    for words, (order, which) in EULER_ORDERS.items():
        yield "euler-order", {"order": words}, p, poses.euler_matrices(q, order, which)
    yield "never-moved", {}, built_p, poses.matrices(built_q)
    yield "translation-only", {}, p, poses.matrices(built_q)
    yield "rotation-only", {}, built_p, r
    for j, other in enumerate(run.drawing.targets):
        if j != i:
            yield "other-target", {"other": f"{other.name!r}"}, physics.now[0][j], poses.matrices(physics.now[1][j])


def _pose(frames, i):
    return frames[0][i], poses.matrices(frames[1][i])


def _event_name(event) -> str:
    name = type(event).__name__
    return {"Teleport": "teleport", "JointReset": "joint reset", "Kick": "kick", "SoftTeleport": "soft-body teleport",
            "SoftKick": "soft-body kick"}.get(name, name.lower())


def explain(run, drawn: Drawn, tolerance: float) -> tuple[str, str] | None:
    """``(mistake, line)`` for target ``drawn.index`` drawn as ``drawn.vertices`` at ``drawn.frame`` with
    per-vertex ``tolerance`` (metres): the first mistake of :data:`MISTAKES` whose pose holds every drawn
    vertex, and the ``diagnosis: …`` line saying so; None when none does."""
    local = run.drawing.local[drawn.index]
    if not len(local) or not np.all(np.isfinite(drawn.vertices)):
        return None
    if run.drawing.targets[drawn.index].nodes is not None:
        return _explain_soft(run, drawn, tolerance)
    physics = drawn.physics
    true_p, true_r = _pose(physics.now, drawn.index)
    truth_vertices = local @ true_r.T + true_p
    allowance = 2 * tolerance
    for name, words, position, matrix in _candidates(run, physics, drawn.index, drawn.frame):
        expected = local @ np.asarray(matrix).T + position
        if np.max(np.linalg.norm(expected - truth_vertices, axis=1)) <= DISTINCT * allowance:
            continue  # this mistake would have drawn it (nearly) right here: it cannot explain the error
        if np.max(np.linalg.norm(expected - drawn.vertices, axis=1)) <= allowance:
            return name, "diagnosis: " + MISTAKES[name].format(**words)
    return None


def _explain_soft(run, drawn: Drawn, tolerance: float) -> tuple[str, str] | None:
    """:func:`explain` for a soft body's target: its vertices tried at the previous step's nodes, at the
    nodes as built, and at the body's nodes now in any order."""
    i, t = drawn.index, run.drawing.targets[drawn.index]
    now = drawn.physics.nodes[i]
    truth_vertices, allowance = now[t.nodes], 2 * tolerance
    built = run.drawing.local[i]
    if i in drawn.physics.untouched:  # whatever its transform, its vertices were never copied from the nodes
        how = "untouched" if np.max(np.linalg.norm(drawn.vertices - built, axis=1)) <= allowance else "posed"
        return "drawn-as-rigid", _as_rigid(t, how)
    candidates = []
    if drawn.physics.previous_nodes is not None and i in drawn.physics.previous_nodes:
        candidates.append(("previous-step", {"frame": drawn.frame - 1}, drawn.physics.previous_nodes[i][t.nodes]))
    if drawn.frame > 0:  # at frame 0 the nodes as built are what the sync's one call was given to copy
        candidates.append(("never-moved", {}, run.drawing.local[i]))
    held = []
    for name, words, expected in candidates:
        if np.max(np.linalg.norm(expected - truth_vertices, axis=1)) <= DISTINCT * allowance:
            continue  # this mistake would have drawn it (nearly) right here: it cannot explain the error
        if np.max(np.linalg.norm(expected - drawn.vertices, axis=1)) <= allowance:
            held.append((name, words))
    if held:
        name, words = held[0]
        # At frame 1 the previous step's nodes are the built ones: the name stays the first that holds
        words_of = "late-or-once" if [n for n, _ in held] == ["previous-step", "never-moved"] else name
        return name, "diagnosis: " + SOFT_WORDS[words_of].format(**words)
    found = _soft_partly(drawn, truth_vertices, candidates, allowance)
    if found:
        return found
    for position, matrix in (drawn.physics.rigid_poses or {}).get(i, ()):
        # its built vertices rewritten at the body's rigid pose, or its nodes moved again by it: alike until
        # the body deforms (at frame 0 the nodes are the built vertices)
        fits = [name for name, expected in (("drawn-as-rigid", built @ matrix.T + position),
                                            ("soft-posed", truth_vertices @ matrix.T + position))
                if np.max(np.linalg.norm(expected - truth_vertices, axis=1)) > DISTINCT * allowance
                and np.max(np.linalg.norm(expected - drawn.vertices, axis=1)) <= allowance]
        if len(fits) == 2:
            return "rigid-or-posed", "diagnosis: " + SOFT_WORDS["rigid-or-posed"].format(name=repr(t.name))
        if fits == ["drawn-as-rigid"]:
            return "drawn-as-rigid", _as_rigid(t, "posed")
        if fits:
            return "soft-posed", "diagnosis: " + SOFT_WORDS["soft-posed"]
    if len(now) > len(t.nodes) and not np.array_equal(t.nodes, np.arange(len(t.nodes))):
        # a volumetric body drawn as if every node were drawn, in order (a sync written for surfaces)
        expected = now[:len(t.nodes)]
        if np.max(np.linalg.norm(expected - truth_vertices, axis=1)) > DISTINCT * allowance and \
                np.max(np.linalg.norm(expected - drawn.vertices, axis=1)) <= allowance:
            return "every-node", "diagnosis: " + SOFT_WORDS["every-node"].format(drawn=len(t.nodes), count=len(now))
    visual = _visual_mesh(run, i, now, drawn.frame)
    if visual is not None and len(visual) > int(np.max(t.nodes, initial=0)):
        expected = visual[t.nodes]  # the visual mesh indexed as the nodes are (or its first vertices: the same)
        if np.max(np.linalg.norm(expected - truth_vertices, axis=1)) > DISTINCT * allowance and \
                np.max(np.linalg.norm(expected - drawn.vertices, axis=1)) <= allowance:
            return "visual-mesh", "diagnosis: " + SOFT_WORDS["visual-mesh"].format(corners=len(visual), count=len(now))
    from scipy.spatial import cKDTree

    distance, nearest = cKDTree(now).query(drawn.vertices)
    if np.all(distance <= allowance) and np.any(nearest != t.nodes):
        return "node-order", "diagnosis: " + MISTAKES["node-order"]
    return None


def _visual_mesh(run, index: int, nodes: np.ndarray, frame: int) -> np.ndarray | None:
    """What ``getMeshData(body)`` without ``MESH_DATA_SIMULATION_MESH`` gives at ``frame`` for the soft body of
    target ``index`` with ``nodes`` now: for a body loaded from a mesh file, each face's corners in the file's
    order (``nodes[faces]``), and before the first step the file's vertices as read, unscaled and unmoved
    (both equal to pyBullet's to the bit on ``soft_ball`` and ``cloth``, tests/test_soft_bodies.py); for a
    volumetric body, its boundary faces' corners at the nodes from the start. None when the scene does not say
    the faces."""
    bindings = getattr(getattr(run, "scene", None), "bindings", None)
    shape = getattr(bindings[index], "shape", None) if bindings and index < len(bindings) else None
    if not getattr(shape, "faces", None):
        return None
    corners = shape.node_faces().reshape(-1)
    if frame == 0 and not shape.volumetric:
        written = getattr(shape, "file_vertices", None)
        # pyBullet reads the file in single precision
        return None if written is None else np.asarray(written, dtype=np.float32).astype(np.float64)[corners]
    return nodes[corners]


def _soft_partly(drawn: Drawn, truth_vertices, candidates, allowance: float) -> tuple[str, str] | None:
    """A soft body's drawing that is its nodes in part, or in a precision too low: some vertices at their nodes
    now and every other one at its node a step late or as built (``part-copied``), or every vertex at its node
    rounded to float16 (``float16``)."""
    off = np.linalg.norm(drawn.vertices - truth_vertices, axis=1)
    right = off <= allowance
    if right.any() and not right.all():
        stale = np.zeros(len(right), dtype=bool)
        for _, _, expected in candidates:
            stale |= np.linalg.norm(drawn.vertices - expected, axis=1) <= allowance
        if np.all(right | stale) and np.any(off[~right] > DISTINCT * allowance):
            return "part-copied", "diagnosis: " + SOFT_WORDS["part-copied"].format(copied=int(right.sum()), count=len(right))
    half = truth_vertices.astype(np.float16).astype(np.float64)
    if np.max(np.linalg.norm(half - truth_vertices, axis=1)) > DISTINCT * allowance and \
            np.max(np.linalg.norm(drawn.vertices - half, axis=1)) <= allowance:
        return "float16", "diagnosis: " + SOFT_WORDS["float16"]
    return None




def undecided(found: tuple[str, str] | None, frame: int) -> tuple[str, str] | None:
    """The two mistakes ``found`` (an :func:`explain` result at ``frame``) cannot tell apart yet, or None."""
    if not found:
        return None
    if found[1] == late_or_once(frame):
        return UNDECIDED["late-or-once"]
    return UNDECIDED.get(found[0])


def late_or_once(frame: int) -> str:
    """The ``diagnosis: …`` line of a soft body copied one step late or only once, not told apart at ``frame``."""
    return "diagnosis: " + SOFT_WORDS["late-or-once"].format(frame=frame - 1)


def _as_rigid(t, how: str) -> str:
    return "diagnosis: " + SOFT_WORDS["drawn-as-rigid"].format(name=repr(t.name), how=_AS_RIGID[how])


def diagnose(run, drawn: Drawn, tolerance: float) -> str:
    """The ``diagnosis: …`` line of :func:`explain`, or ``""``."""
    found = explain(run, drawn, tolerance)
    return found[1] if found else ""


def soft_names(run) -> set[str]:
    """The names of ``run``'s soft bodies' targets (``Target.nodes`` is not None)."""
    return {t.name for t in run.drawing.targets if t.nodes is not None}


def explain_failures(run, drawn: dict[str, Drawn], worst, failures) -> tuple[str, str] | None:
    """:func:`explain` for a frame's failing vertex results ``failures``: a soft body drawn as a rigid one
    first, whichever target is the worst (a sync written before soft bodies is told so before anything
    else), then the worst result's (``worst``) mistake. ``drawn``: what the failing targets are drawn as
    (:func:`drawn_now`; those not in it are not tried)."""
    soft = soft_names(run)
    for result in sorted((r for r in failures if r.target in soft and r.target in drawn), key=lambda r: r is not worst):
        found = explain(run, drawn[result.target], result.tolerance)
        if found and found[0] == "drawn-as-rigid":
            return found
    return explain(run, drawn[worst.target], worst.tolerance) if worst.target in drawn else None


def explain_frame(run, results) -> tuple[str, str] | None:
    """:func:`explain` for the failing vertex results of ``run`` as it stands now: a soft body drawn as a
    rigid one, else the worst (in tolerances) result's mistake."""
    failing = [r for r in results if not r.ok]
    if not failing:
        return None
    worst = max(failing, key=lambda r: r.error / r.tolerance if r.tolerance else r.error)
    soft = soft_names(run)
    drawn = drawn_now(run, {worst.target} | {r.target for r in failing if r.target in soft}, worst.frame)
    return explain_failures(run, drawn, worst, failing)


def soft_drawn_as_rigid(run, tolerance=None) -> str:
    """The ``diagnosis: …`` line of a soft body of ``run`` drawn, as it stands now, as a rigid body (the
    picture checks' failures lead with it), or ``""``: none is, or the run has no soft body."""
    from conformance.judge import compare

    soft = soft_names(run)
    if not soft:
        return ""
    results = compare.compare_vertices(run.drawing, run.frame, *([tolerance] if tolerance is not None else []))
    failing = [r for r in results if not r.ok and r.target in soft]
    if not failing:
        return ""
    drawn = drawn_now(run, {r.target for r in failing}, run.frame)
    found = explain_failures(run, drawn, failing[0], failing)
    return found[1] if found and found[0] == "drawn-as-rigid" else ""


def diagnose_frame(run, results) -> str:
    """The ``diagnosis: …`` line of :func:`explain_frame`, or ``""``."""
    found = explain_frame(run, results)
    return found[1] if found else ""


def explain_normals(run, result) -> tuple[str, str] | None:
    """``(mistake, line)`` for a failing normals result (:class:`conformance.judge.compare.NormalResult`): the
    first of :data:`NORMAL_MISTAKES` whose rotation turns the target's built normals into the drawn ones
    within twice the angle tolerance; None when none does (or the target's vertices are wrong too,
    which the vertex diagnosis covers)."""
    from conformance import backends

    names = [t.name for t in run.drawing.targets]
    if result.target not in names:
        return None
    i = names.index(result.target)
    t, local = run.drawing.targets[i], run.drawing.local_normals[i]
    if local is None:
        return None
    stored = backends.world_normals(t.actor)
    if stored is None:
        return "normals-dropped", "diagnosis: " + NORMAL_MISTAKES["normals-dropped"]
    drawn = np.asarray(stored, dtype=np.float64)[t.start:t.stop]
    if drawn.shape != local.shape or not np.all(np.isfinite(drawn)):
        return None
    r = poses.matrices(run.poses()[1][i])
    unit = local / np.linalg.norm(local, axis=1, keepdims=True)
    drawn = drawn / np.linalg.norm(drawn, axis=1, keepdims=True)
    allowance = 2 * result.tolerance

    def candidates():
        previous = run.previous if result.frame == run.frame else None
        if previous is not None:
            yield "normals-previous-step", {"frame": result.frame - 1}, poses.matrices(previous[1][i])
        yield "stale-normals", {}, poses.matrices(np.asarray(t.orientation, dtype=np.float64))
        yield "normals-twice", {}, r @ r
        yield "normals-inverse", {}, r.T

    held = []
    for name, words, matrix in candidates():
        candidate = unit @ matrix.T
        if np.max(_angles(candidate, unit @ r.T)) <= DISTINCT * allowance:
            continue  # this mistake would have lit it (nearly) right here: it cannot explain the error
        if np.max(_angles(candidate, drawn)) <= allowance:
            held.append((name, words))
    if not held:
        return None
    name, words = held[0]
    if [n for n, _ in held[:2]] == ["normals-previous-step", "stale-normals"]:
        name = "stale-or-late-normals"  # the previous step's rotation is still the built one
    return name, "diagnosis: " + NORMAL_MISTAKES[name].format(**words)


def _angles(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.arccos(np.clip(np.einsum("kj,kj->k", a, b), -1.0, 1.0))


def diagnose_normals(run, result) -> str:
    """The ``diagnosis: …`` line of :func:`explain_normals`, or ``""``."""
    found = explain_normals(run, result)
    return found[1] if found else ""


def unannounced() -> str:
    """The ``diagnosis: …`` line of a change the sync made without announcing it."""
    from conformance import backends

    return "diagnosis: " + NORMAL_MISTAKES["unannounced"].format(announce=backends.ANNOUNCE)


def diagnose_problems(run) -> str:
    """The diagnosis of the worst problem of ``run`` as it stands now, in the order the checks report
    them: wrong vertices, then wrong normals, then a change not announced; ``""`` when none is known."""
    from conformance.judge import compare

    vertices = compare.compare_vertices(run.drawing, run.frame)
    if not all(r.ok for r in vertices):
        return diagnose_frame(run, vertices)
    normals = [r for r in compare.compare_normals(run.drawing, run.frame) if not r.ok]
    if normals:
        return diagnose_normals(run, max(normals, key=lambda r: r.angle))
    if any(frame == run.frame for frame, *_ in run.unannounced):
        return unannounced()
    return ""


def name_of(line: str) -> str:
    """The catalogue's name of the mistake a ``diagnosis: …`` line (or what follows its label) states, or ""
    for a line it did not write: how a record kept as text (the plugin's ``diagnosis``) is counted by name
    (``python -m conformance confusion``)."""
    text = line.strip()
    text = text[len("diagnosis: "):] if text.startswith("diagnosis: ") else text
    for name, pattern in _patterns():
        if pattern.match(text):
            return name
    return ""


def _patterns():
    import re

    if not _PATTERNS:
        words = {**{f"soft {k}": v for k, v in SOFT_WORDS.items()}, **NORMAL_MISTAKES, **MISTAKES}
        for key, template in sorted(words.items(), key=lambda kv: -len(kv[1])):  # the longest (most specific) first
            parts = re.split(r"\{[a-z_]*\}", template)
            name = key.removeprefix("soft ")
            # what follows the words (a note on how the mistake was told) is not part of them
            _PATTERNS.append((name, re.compile(".*?".join(map(re.escape, parts)), re.S)))
    return _PATTERNS


_PATTERNS: list = []
