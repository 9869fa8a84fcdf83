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


def attached(track, attachment, pieces: dict, verdict) -> None:
    """One ``attached`` line per soft body and mistake for the loose vertices that follow its nodes
    (``pieces``: ``(client, body, name, diagnosis) -> [Piece]``): a cloth drawn one step late is one
    mistake, not one line per vertex. Vertices named nothing that move as one rigid piece are a soft body
    posed as a rigid one (``drawn-as-rigid``)."""
    for (client, body, label, diagnosis), found in pieces.items():
        rows = np.concatenate([piece.rows for piece in found])
        if not diagnosis and _rigid(track.vertices[1:, rows], max(piece.allowed for piece in found)):
            diagnosis = "drawn-as-rigid"
        first = min(found, key=lambda piece: piece.first_tick)
        worst = max(found, key=lambda piece: piece.worst_error)
        verdict.lines.append(
            f"{track.label} ({track.kind}) vertices {vertex_ranges(rows)} of {len(attachment.frame)}: not held by "
            f"any frame; each follows a node of {name(client, body, label)} best, and the first left it at tick "
            f"{first.first_tick + 1}: {first.first_error:.3g} m from that node (allowed "
            f"{max(piece.allowed for piece in found):.3g} m); worst {worst.worst_error:.3g} m at tick {worst.worst_tick + 1}")
        verdict.diagnosed(diagnosis)


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
    them. A node pyBullet does not draw (inside a tetrahedral body: ``Frame.shown`` 0) need not be drawn."""
    r = judgement.r
    for (client, body), nodes in _nodes_by_body(r.frames).items():
        nodes = [i for i in nodes if r.frames[i].shown != 0]
        if not nodes:
            continue
        allowance = 10 * judgement.tolerance.for_extents(np.zeros(len(nodes)), judgement.pos[0, nodes])
        moved = np.array([judgement._movement(i, 0.0) for i in nodes])
        missing = [i for i, m, a in zip(nodes, moved, allowance) if m > a and i not in followed]
        if not missing:
            continue
        verdict.passed = False
        numbers = [r.frames[i].node for i in missing]
        shown = ", ".join(map(str, numbers[:8])) + (f" … ({len(numbers)} of {len(nodes)})" if len(numbers) > 8 else "")
        left = _left_at_nodes(judgement, missing)
        verdict.lines.append(f"{name(client, body, r.frames[nodes[0]].name)}: node{'s' if len(numbers) > 1 else ''} "
                             f"{shown} move (up to {max(moved[nodes.index(i)] for i in missing):.3g} m over ticks "
                             f"1..{r.ticks}) but no drawn vertex follows them: copy every node of getMeshData(body, -1, "
                             "flags=p.MESH_DATA_SIMULATION_MESH) into the actor after each step"
                             + (f"; {left} stay where they were built, on those nodes" if left else ""))
        if left:
            verdict.diagnosed("never-moved")


def _left_at_nodes(judgement, nodes: list[int]) -> str:
    """The actor ranges held by the world that were drawn, when the loop started, on ``nodes`` (frame
    indices): a soft body drawn once and never copied again."""
    from scipy.spatial import cKDTree

    r = judgement.r
    tree = cKDTree(r.positions[0, nodes])
    found = []
    for track, a in zip(r.actors, judgement.attachments):
        world = np.flatnonzero((a.frame < 0) & a.held)
        if not len(world):
            continue
        distance, _ = tree.query(track.vertices[0, world])
        allowed = 10 * judgement.tolerance.for_extents(np.zeros(len(world)), track.vertices[0, world])
        on = world[distance <= allowed]
        if len(on):
            found.append(f"{track.label} vertices {vertex_ranges(on)}")
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
        worst = max(off, key=lambda piece: piece[2][0] / max(piece[2][1], 1e-300))
        off_rows = np.sort(np.concatenate([piece[0] for piece in off]))
        verdict.lines.append(
            f"{label} vertices {vertex_ranges(off_rows)} ({len(off_rows)} of the {len(rows)} that follow nodes of "
            f"{soft_body}) are not drawn at the node they follow: vertices {vertex_ranges(worst[0])} follow node "
            f"{judgement.r.frames[worst[1]].node} {worst[2][0]:.3g} m away from it (allowed {worst[2][1]:.3g} m)")
        verdict.diagnosed("node-order")
