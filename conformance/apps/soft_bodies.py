"""Judging drawings of soft bodies (``loadSoftBody``, deformable URDFs): what ``attached``, ``drawn`` and
``placed`` ask of the vertices that follow a soft body's simulated nodes (docs/apps.md, "Soft bodies").

Each node is a frame with a position and no turn (:attr:`conformance.apps.bodies.Frame.node`), so the
rigid machinery finds which node holds each vertex. What differs is said here: the vertices that follow
one soft body are judged, and named, together; every node that moves must be followed; and what follows
a node is drawn at it, a node having no shape to be drawn on.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from conformance.apps.recording import vertex_ranges

__all__ = ["Piece", "attached", "drawn", "name", "off_node", "placed"]


def name(client: int, body: int, label: str) -> str:
    """``soft body 0 (cloth_z_up)``; on a client other than 0, ``client 1 soft body 0 (…)``."""
    return f"{'client %d ' % client if client else ''}soft body {body} ({label})"


@dataclass(frozen=True)
class Piece:
    """A run of an actor's loose vertices that follows one node best, and its errors: at the tick it first
    left the node, and at its worst tick."""

    rows: np.ndarray
    first_error: float
    first_tick: int
    worst_error: float
    worst_tick: int
    allowed: float
    frame: int = -1     # the node's frame it follows best


def attached(judgement, track, attachment, pieces: dict, verdict) -> None:
    """One ``attached`` line per soft body and mistake for the loose vertices that follow its nodes
    (``pieces``: ``(client, body, name, diagnosis) -> [Piece]``): a cloth drawn one step late is one
    mistake, not one line per vertex. Vertices named nothing are named by what they are instead of the
    nodes: the built shape moved as one rigid piece (``drawn-as-rigid``), the nodes rounded to half
    precision (``float16``), or the nodes moved again by a pose of the actor (``soft-posed``)."""
    for (client, body, label, diagnosis), found in pieces.items():
        rows = np.concatenate([piece.rows for piece in found])
        allowed = max(piece.allowed for piece in found)
        if not diagnosis:
            diagnosis = _named(judgement, track, found, rows, allowed, (client, body))
        first = min(found, key=lambda piece: piece.first_tick)
        worst = max(found, key=lambda piece: piece.worst_error)
        verdict.lines.append(
            f"{track.label} ({track.kind}) vertices {vertex_ranges(rows)} of {len(attachment.frame)}: not held by "
            f"any frame; each follows a node of {name(client, body, label)} best, and the first left it at tick "
            f"{first.first_tick + 1}: {first.first_error:.3g} m from that node (allowed "
            f"{allowed:.3g} m); worst {worst.worst_error:.3g} m at tick {worst.worst_tick + 1}")
        verdict.diagnosed(diagnosis)
        judgement.soft_misdrawn.add((client, body))


def _named(judgement, track, found, rows, allowed: float, body: tuple) -> str:
    """The mistake of a soft body's loose vertices that no variant of the rigid machinery names, or ""."""
    vertices = track.vertices[1:, rows]
    if _rigid(vertices, allowed):
        return "drawn-as-rigid"
    nodes = np.concatenate([np.repeat(judgement.pos[:, [piece.frame]], len(piece.rows), axis=1) for piece in found], axis=1)
    half = nodes.astype(np.float16).astype(np.float64)
    # named only where rounding moves a node well past the allowance: the drawing is then nearer the rounded
    # nodes than the nodes themselves
    if np.max(np.linalg.norm(half - nodes, axis=-1)) > 3 * allowed and \
            np.max(np.linalg.norm(vertices - half, axis=-1)) <= allowed:
        return "float16"
    frames = _nodes_by_body(judgement.r.frames).get(body, [])
    if frames and _posed(vertices, rows, judgement.pos[:, frames], allowed):
        return "soft-posed"
    return ""


def _posed(vertices: np.ndarray, rows: np.ndarray, nodes: np.ndarray, allowance: float) -> bool:
    """Whether ``vertices`` (ticks, n, 3) are the soft body's ``nodes`` (ticks, m, 3) moved again at every tick
    by one rigid pose, a pose that does move them: what a soft body's actor draws when the program gives it
    a pose (the body's getBasePositionAndOrientation, as for its rigid bodies) on top of the nodes, which
    are already in the world's frame. The actor's vertex k (``rows``) pairs with node k (an actor built from
    the nodes in their order), or with the node nearest it once the first tick's centres are put together."""
    from scipy.spatial import cKDTree
    from scipy.spatial.transform import Rotation

    n = vertices.shape[1]
    if n < 3 or not len(vertices):
        return False
    pairings = [rows] if rows.max() < nodes.shape[1] else []
    shift = nodes[0].mean(axis=0) - vertices[0].mean(axis=0)
    pairings.append(cKDTree(nodes[0]).query(vertices[0] + shift)[1])
    for pairing in pairings:
        moved, fits = False, True
        for drawn, now in zip(vertices, nodes[:, pairing]):
            centre, at = drawn.mean(axis=0), now.mean(axis=0)
            turn, _ = Rotation.align_vectors(drawn - centre, now - at)
            if np.max(np.linalg.norm(turn.apply(now - at) + centre - drawn, axis=1)) > allowance:
                fits = False
                break
            moved = moved or np.max(np.linalg.norm(drawn - now, axis=1)) > 10 * allowance
        if fits and moved:
            return True
    return False


def _rigid(vertices: np.ndarray, allowance: float) -> bool:
    """Whether ``vertices`` (ticks, n, 3) move as one rigid piece that does move: at every tick a turn and a shift
    of the first tick's within ``allowance``, and further than that from where they began. Vertices held by no
    node move so only when a soft body is drawn as a rigid one (were the body itself rigid here, its nodes
    would hold them)."""
    if len(vertices) < 3 or vertices.shape[1] < 4:
        return False
    from scipy.spatial.transform import Rotation

    first = vertices[0] - vertices[0].mean(axis=0)
    moved = False
    for now in vertices[1:]:
        centre = now.mean(axis=0)
        turn, _ = Rotation.align_vectors(now - centre, first)
        if np.max(np.linalg.norm(turn.apply(first) + centre - now, axis=1)) > allowance:
            return False
        moved = moved or np.max(np.linalg.norm(now - vertices[0], axis=1)) > 10 * allowance
    return moved


def _nodes_by_body(frames) -> dict[tuple[int, int], list[int]]:
    """The node frames of each soft body, by (client, body)."""
    found: dict[tuple[int, int], list[int]] = {}
    for index, frame in enumerate(frames):
        if frame.node >= 0:
            found.setdefault((frame.client, frame.body), []).append(index)
    return found


def drawn(judgement, verdict, followed: set) -> None:
    """A soft body is drawn when every node of it that moves and that pyBullet draws is followed by some drawn
    vertex: a program that copies all but the last nodes, or none, leaves nodes moving with nothing drawn on
    them. A node pyBullet does not draw (inside a tetrahedral body: ``Frame.shown`` 0) need not be drawn.
    Vertices left on such nodes where they were built are the mistake named: ``never-moved`` when no moving
    node is followed, ``part-copied`` when some are (the copy stops short)."""
    r = judgement.r
    for (client, body), nodes in _nodes_by_body(r.frames).items():
        nodes = [i for i in nodes if r.frames[i].shown != 0]
        if not nodes:
            continue
        allowance = 10 * judgement.tolerance.for_extents(np.zeros(len(nodes)), judgement.pos[0, nodes])
        moved = np.array([judgement._movement(i, 0.0) for i in nodes])
        moving = [i for i, m, a in zip(nodes, moved, allowance) if m > a]
        missing = [i for i in moving if i not in followed]
        if not missing:
            continue
        verdict.passed = False
        judgement.soft_misdrawn.add((client, body))
        numbers = [r.frames[i].node for i in missing]
        shown = ", ".join(map(str, numbers[:8])) + (f" … ({len(numbers)} of {len(nodes)})" if len(numbers) > 8 else "")
        left = _left_at_nodes(judgement, missing)
        verdict.lines.append(f"{name(client, body, r.frames[nodes[0]].name)}: node{'s' if len(numbers) > 1 else ''} "
                             f"{shown} move (up to {max(moved[nodes.index(i)] for i in missing):.3g} m over ticks "
                             f"1..{r.ticks}) but no drawn vertex follows them: copy every node of getMeshData(body, -1, "
                             "flags=p.MESH_DATA_SIMULATION_MESH) into the actor after each step"
                             + (f"; {left} stay where they were built, on those nodes" if left else ""))
        if left:
            copied = len(moving) - len(missing)
            if copied:
                verdict.lines[-1] += f" ({copied} of its {len(moving)} moving nodes are copied)"
            verdict.diagnosed("part-copied" if copied else "never-moved")


def _left_at_nodes(judgement, nodes: list[int]) -> str:
    """The actor ranges that were drawn, when the loop started, on ``nodes`` (frame indices) and never moved:
    a soft body drawn once and never copied again. They are held by the world, or by a frame that never
    moves either (an anchored corner of the same cloth holds every still vertex as well), and are the
    copy's mistake, not a drawing of that frame: :attr:`judgement.left_behind` keeps them from ``placed``."""
    from scipy.spatial import cKDTree

    r = judgement.r
    tree = cKDTree(r.positions[0, nodes])
    found = []
    for index, (track, a) in enumerate(zip(r.actors, judgement.attachments)):
        allowed = 10 * judgement.tolerance.for_extents(np.zeros(len(a.frame)), track.vertices[0])
        still = np.max(np.linalg.norm(track.vertices - track.vertices[:1], axis=-1), axis=0) <= allowed
        candidates = np.flatnonzero(a.held & still)
        if not len(candidates):
            continue
        distance, _ = tree.query(track.vertices[0, candidates])
        on = candidates[distance <= allowed[candidates]]
        if len(on):
            found.append(f"{track.label} vertices {vertex_ranges(on)}")
            judgement.left_behind.setdefault(index, set()).update(on.tolist())
    return ", ".join(found)


def off_node(judgement, offsets: np.ndarray, frame: int) -> tuple[float, float]:
    """How far the centre of the vertices a node holds lies from the node, and what is allowed: a drawing
    that follows a node is drawn at it (a vertex on it, or a small sphere around it), as the rigid checks
    ask a drawing's centre to be its shape's."""
    centre = offsets.mean(axis=0)
    spread = float(np.max(np.linalg.norm(offsets - centre, axis=1), initial=0.0))
    allowed = 10 * judgement.tolerance.for_extents(np.array([spread]), judgement.pos[:1, frame])[0]
    return float(np.linalg.norm(centre)), float(allowed)


def placed(judgement, pieces: dict, verdict) -> None:
    """``placed`` for the vertices that follow nodes (``pieces``: ``(actor label, client, body, name) ->
    [(rows, frame, off_node)]``): each drawn at its node, or a ``node-order`` failure naming the worst."""
    for (label, client, body, body_name), found in pieces.items():
        rows = np.sort(np.concatenate([piece[0] for piece in found]))
        soft_body = name(client, body, body_name)
        off = [piece for piece in found if piece[2][0] > piece[2][1]]
        if not off:
            verdict.notes.append(f"{label} vertices {vertex_ranges(rows)} follow nodes of {soft_body}, each drawn at its node")
            continue
        verdict.passed = False
        judgement.soft_misdrawn.add((client, body))
        worst = max(off, key=lambda piece: piece[2][0] / max(piece[2][1], 1e-300))
        off_rows = np.sort(np.concatenate([piece[0] for piece in off]))
        verdict.lines.append(
            f"{label} vertices {vertex_ranges(off_rows)} ({len(off_rows)} of the {len(rows)} that follow nodes of "
            f"{soft_body}) are not drawn at the node they follow: vertices {vertex_ranges(worst[0])} follow node "
            f"{judgement.r.frames[worst[1]].node} {worst[2][0]:.3g} m away from it (allowed {worst[2][1]:.3g} m)")
        verdict.diagnosed("node-order")
