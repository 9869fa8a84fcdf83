"""Rigid attachment: which frame holds each drawn vertex, and from which tick it stops holding it.

A vertex drawn right is fixed in the link frame of one body or link (or in the world): its coordinates
in that frame are the same at every tick. So, with no mapping from the user, the kit finds for each
vertex the frame in which its coordinates vary least, and holds them to the kit's vertex tolerance
there (:mod:`conformance.judge.tolerances`: the same float32 and pybullet-helper budget as for a scene, per
frame and actor). Because the reference coordinates are themselves read from the drawing (their
median over the ticks), a vertex may be off by the tolerance at a tick and by the tolerance in the
reference: the allowance is twice the tolerance.

What this cannot decide, and what decides it: two frames that never move relative to each other
(a body at rest on a static one, a static body and the world, two bodies released side by side) hold
the same vertices equally; the kit then gives each vertex to the frame whose collision shape it lies on
(the world only when no body holds it) and says so, and its own events (:mod:`conformance.apps.perturb`) move
dynamic bodies apart. What it cannot see: a drawing held rigidly by the *right* frame at the wrong
place in it (drawn at the centre of mass, a vertex range following another body):
:mod:`conformance.apps.placement` judges where in its frame a drawing sits.

Variants of a frame (:data:`VARIANTS`) are the poses of the usual mistakes; a vertex that no frame
holds but a variant does is diagnosed by it.
"""

from __future__ import annotations

import functools

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation

from conformance.bullet import poses
from conformance.judge.tolerances import DEFAULT, Tolerance

__all__ = ["ALIASES", "Attachment", "TURNS", "VARIANTS", "attach", "bad_ticks", "in_frame", "local_coordinates", "rotations", "runs",
           "variant_fit", "visual_order"]

#: nearest frames (by origin, at the first judged tick) tried first for each vertex, then more of
#: them for a vertex none of those holds, then all of them (so a range following a far body is found)
FIRST = 4
NEAREST = 32
#: ticks compared when choosing a vertex's frame (all ticks are compared once it is chosen)
PROBES = 8
#: a vertex this close (m) to a welded frame's collision shape lies on it
ON_SHAPE = 1e-4


@dataclass
class Attachment:
    """For each vertex of one actor: ``frame`` (index into the recording's frames, ``-1`` the world),
    ``error`` ``(T,)`` per judged tick (metres from where that frame carries it), ``allowance`` (twice
    the tolerance), ``reference`` (its coordinates in that frame), and ``tied`` (another frame holds it
    as well: undecidable from this run)."""

    frame: np.ndarray      # (n,) int
    error: np.ndarray      # (n, T) float
    allowance: np.ndarray  # (n,) float
    reference: np.ndarray  # (n, 3)
    tied: np.ndarray       # (n,) bool
    #: held by frames welded together (:mod:`conformance.apps.welds`), and given to the one whose shape it lies on
    welded: np.ndarray | None = None

    @functools.cached_property
    def held(self) -> np.ndarray:
        return np.all(self.error <= self.allowance[:, None], axis=1)


def _world(positions: np.ndarray, rotations: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Frame poses with the world appended as the last frame."""
    t = positions.shape[0]
    pos = np.concatenate([positions, np.zeros((t, 1, 3))], axis=1)
    rot = np.concatenate([rotations, np.broadcast_to(np.eye(3), (t, 1, 3, 3))], axis=1)
    return pos, rot


def local_coordinates(vertices: np.ndarray, positions: np.ndarray, rotations: np.ndarray) -> np.ndarray:
    """``vertices`` ``(T, n, 3)`` in the frames ``(T, n, 3)`` / ``(T, n, 3, 3)`` (one frame per vertex): ``Rᵀ (v - p)``."""
    return _transposed_times(rotations, vertices - positions)


def _transposed_times(rotations: np.ndarray, vectors: np.ndarray) -> np.ndarray:
    """``Rᵀ d`` for stacks of 3x3 ``rotations`` and 3-vectors ``vectors``: three multiply-adds over whole
    arrays, several times faster than the equivalent einsum on the judge's (ticks, vertices) stacks."""
    return (vectors[..., 0, None] * rotations[..., 0, :] + vectors[..., 1, None] * rotations[..., 1, :]
            + vectors[..., 2, None] * rotations[..., 2, :])


def in_frame(vertices: np.ndarray, positions: np.ndarray, rotations: np.ndarray) -> np.ndarray:
    """``(T, m, 3)``: vertices ``(T, m, 3)`` in one frame, posed ``(T, 3)`` / ``(T, 3, 3)`` at each tick:
    ``Rᵀ (v - p)`` as one matrix product a tick (``(Rᵀ d)ᵀ = dᵀ R``)."""
    return (vertices - positions[:, None, :]) @ rotations


def _in_frames(vertices: np.ndarray, pos: np.ndarray, rot: np.ndarray, best: np.ndarray, rows=None) -> np.ndarray:
    """``(T, m, 3)``: the vertices ``rows`` (all by default) in their frames ``best[rows]`` at every tick, one
    matrix product per frame: a ``(T, n, 3, 3)`` stack of each vertex's rotation, gathered, cost 4.5 times
    as much on a racecar's 30,000-vertex chassis (``(R^T d)^T = d^T R``)."""
    rows = np.arange(len(best)) if rows is None else np.asarray(rows)
    frames = best[rows]
    local = np.empty((vertices.shape[0], len(rows), 3))
    for f in np.unique(frames):
        mine = np.flatnonzero(frames == f)
        local[:, mine] = in_frame(vertices[:, rows[mine]], pos[:, f], rot[:, f])
    return local


def _lengths(d: np.ndarray) -> np.ndarray:
    """Euclidean lengths over the last axis (``np.linalg.norm``'s, six times as fast on these stacks)."""
    return np.sqrt(np.einsum("...i,...i->...", d, d))


#: A vertex whose coordinates in its frame stay within this fraction of its allowance of their first tick's is
#: measured from those, not from their median over the ticks: both lie that close to every tick's, so whether
#: it is held cannot change and its error moves by at most that fraction of the allowance. The median, a
#: partition of every vertex's ticks, was most of judging a racecar (a 30,000-vertex chassis, twice a run).
STILL = 1e-3


def _centres(local: np.ndarray, still: np.ndarray | None = None) -> np.ndarray:
    """``(m, 3)``: each vertex's median coordinates over the ticks of ``local`` ``(T, m, 3)``; with ``still``
    ``(m,)``, a vertex whose coordinates all lie within ``still`` of the first tick's has those."""
    if still is None or not local.shape[0]:
        return np.median(local, axis=0)
    first = local[0]
    moving = np.flatnonzero(np.max(_lengths(local - first), axis=0) > still)
    centres = np.array(first)
    if len(moving):
        centres[moving] = np.median(local[:, moving], axis=0)
    return centres


def _errors(local: np.ndarray, still: np.ndarray | None = None) -> np.ndarray:
    """``(m, T)``: each vertex's distance from its median coordinates (:func:`_centres`), at every tick."""
    return _lengths(local - _centres(local, still)).T


def _spreads(vertices, positions, rotations, candidates, probes):
    """Largest change of each vertex's coordinates over the ``probes`` ticks, in each candidate frame:
    ``(n, k)`` for ``candidates`` ``(n, k)`` frame indices (computed frame by frame, as :func:`_in_frames`); a
    pair whose frame is -1 is not computed: infinity."""
    v, p, r = vertices[probes], positions[probes], rotations[probes]
    out = np.empty(candidates.shape)
    for f in np.unique(candidates):
        rows, cols = np.nonzero(candidates == f)
        if f < 0:  # a pair not asked for
            out[rows, cols] = np.inf
            continue
        local = in_frame(v[:, rows], p[:, f], r[:, f])
        out[rows, cols] = np.max(_lengths(local - local[:1]), axis=0)
    return out


def _probes(ticks: int, extra=()) -> np.ndarray:
    chosen = set(np.linspace(0, ticks - 1, min(PROBES, ticks)).round().astype(int).tolist())
    chosen.update(t for t in extra if 0 <= t < ticks)
    return np.array(sorted(chosen))


def attach(vertices: np.ndarray, positions: np.ndarray, rotations: np.ndarray, *, tolerance: Tolerance = DEFAULT,
           event_ticks=(), centres: np.ndarray | None = None, radii: np.ndarray | None = None,
           groups: np.ndarray | None = None, outside=None) -> Attachment:
    """Find the frame holding each vertex and its error at every tick.

    ``vertices`` ``(T, n, 3)`` are one actor's drawn vertices at the judged ticks; ``positions``
    ``(T, F, 3)`` and ``rotations`` ``(T, F, 3, 3)`` the link frames at the same ticks. Every vertex is
    tried in its :data:`FIRST` nearest frames and the world; one that none of them holds in its
    :data:`NEAREST` nearest, then in every frame (so a range following a far-away body is still found).
    ``centres`` ``(F, 3)`` and ``radii`` ``(F,)`` are the frames' collision shapes (centre in the frame,
    bounding radius), to choose between frames that hold a vertex equally; by default the frame origins
    and 1 m. ``groups`` ``(F,)`` are the welded frames (:func:`conformance.apps.welds.groups`): a vertex
    held by one of them goes to the member whose shape it lies on (``outside(frame, points)``: how far
    link-frame points lie outside the frame's shapes), whichever of them it was tried in."""
    ticks, n, _ = vertices.shape
    frames = positions.shape[1]
    centres = np.zeros((frames, 3)) if centres is None else np.asarray(centres, dtype=np.float64)
    radii = np.ones(frames) if radii is None else np.maximum(np.asarray(radii, dtype=np.float64), 1e-6)
    pos, rot = _world(positions, rotations)
    probes = _probes(ticks, [t - 1 for t in event_ticks] + list(event_ticks))
    # Nearest by where each frame's shape is, not its origin: a gear whose link frame sits on another
    # gear's axle is still nearest its own teeth.
    tree = cKDTree(positions[0] + _transposed_times(np.swapaxes(rotations[0], -1, -2), centres)) if frames else None

    def nearest(rows: np.ndarray, k: int) -> np.ndarray:
        """The ``k`` frames nearest each of ``rows`` at the first tick, and the world."""
        found = np.asarray(tree.query(vertices[0, rows], k=k)[1]).reshape(len(rows), k) if k else np.zeros((len(rows), 0), int)
        return np.concatenate([found, np.full((len(rows), 1), frames)], axis=1)

    def spreads_of(rows: np.ndarray, candidates: np.ndarray, probes: np.ndarray = probes) -> np.ndarray:
        # bounded memory: (probes, step, k, 3, 3) at a time, as much as PROBES ticks of 131,072 vertices
        step = max(1, 131072 * PROBES // (candidates.shape[1] * max(len(probes), 1)))
        return np.concatenate([_spreads(vertices[:, rows[i:i + step]], pos, rot, candidates[i:i + step], probes)
                               for i in range(0, len(rows), step)]) if len(rows) else np.zeros((0, candidates.shape[1]))

    # Most vertices are held by one of their few nearest frames: try those first, then more, then all.
    everyone = np.arange(n)
    candidates = nearest(everyone, min(frames, FIRST))
    spreads = spreads_of(everyone, candidates)
    best = candidates[everyone, np.argmin(spreads, axis=1)] if n else np.zeros(0, dtype=int)
    allowance = _allowance(vertices, pos, rot, best, tolerance)
    # Frames that hold a vertex within the tolerance hold it equally (two bodies falling side by side from
    # rest keep their relative pose): the one it is drawn on is the one whose shape it lies on (smallest
    # distance from the shape's centre over the shape's radius), not the one whose spread happens to be
    # smallest by rounding; the world only when no body holds it.
    holding = spreads <= allowance[:, None]
    closeness = np.where(holding, _shape_distance(vertices[0], pos[0], rot[0], candidates, centres, radii), np.inf)
    if outside is not None and n:
        closeness = _on_a_shape_first(vertices[0], pos[0], rot[0], candidates, holding, closeness, outside, frames)
    choice = np.where(holding.any(axis=1), np.argmin(closeness, axis=1), np.argmin(spreads, axis=1)) if n else np.zeros(0, int)
    best = candidates[everyone, choice] if n else np.zeros(0, dtype=int)
    best_spread = spreads[everyone, choice] if n else np.zeros(0)
    allowance = _allowance(vertices, pos, rot, best, tolerance)
    if outside is not None and n and frames > FIRST:
        # Held by several of its nearest frames, and on none of their shapes: its own may not be among them.
        stray = np.zeros(n, dtype=bool)
        tied_rows = np.flatnonzero((holding.sum(axis=1) >= 2) & (best < frames))
        stray[tied_rows] = _gaps(outside, vertices, pos, rot, tied_rows, best[tied_rows]) > ON_SHAPE
        _onto_a_shape(vertices, pos, rot, best, best_spread, allowance, outside, tolerance,
                      lambda rows: nearest(rows, min(frames, NEAREST))[:, :-1], spreads_of, stray)
        allowance = _allowance(vertices, pos, rot, best, tolerance)
    for k in (NEAREST, frames):
        loose = np.flatnonzero(best_spread > allowance)
        if not len(loose) or k <= min(frames, FIRST):
            continue
        wider = nearest(loose, k) if k < frames else np.broadcast_to(np.arange(frames + 1), (len(loose), frames + 1))
        found = spreads_of(loose, wider)
        better = found.min(axis=1) < best_spread[loose]
        best[loose[better]] = wider[better, np.argmin(found[better], axis=1)]
        best_spread[loose[better]] = found[better].min(axis=1)
        allowance = _allowance(vertices, pos, rot, best, tolerance)
        if k >= frames:
            break
    tied = np.sum(spreads <= np.maximum(allowance, 1e-12)[:, None], axis=1) > 1 if n else np.zeros(0, dtype=bool)
    local = _in_frames(vertices, pos, rot, best)
    error = _errors(local, STILL * allowance)

    def again_in(rows):
        """Recompute ``local`` and ``error`` of the ``rows`` whose frame changed."""
        local[:, rows] = _in_frames(vertices, pos, rot, best, rows)
        error[rows] = _errors(local[:, rows], STILL * allowance[rows])

    # The frame was chosen on the probe ticks, where two frames may both hold a vertex (the corner where two
    # resting bricks touch lies on both shapes) though only one holds it at every tick: choose those again
    # on every tick (measured on FURY's own wrecking-ball demo: single corners "not held" 1e-13 m from their brick).
    def choose_again(rows):
        """Give each of ``rows`` not held at every tick the frame among its nearest that holds it best at every tick."""
        nonlocal allowance
        loose = rows[np.any(error[rows] > allowance[rows, None], axis=1)]
        if len(loose):
            again = np.concatenate([nearest(loose, min(frames, NEAREST)), best[loose, None]], axis=1)
            limit = _allowances_in(vertices, pos, rot, best, again, tolerance)
            # A spread over the probe ticks (tick 0 among them) is at most the spread over every tick: the
            # frame nearest on the probes gives the smallest spread an upper bound, and a frame whose probe
            # spread is above that bound and its own allowance can neither hold the vertex nor come nearest.
            # The same choice as every frame's spread over every tick, at a fraction of the cost on a wrong
            # drawing, where every vertex is loose (a racecar drawn before its own resets: most of its judging).
            bound = spreads_of(loose, again)
            each = np.arange(len(loose))
            first = np.argmin(bound, axis=1)
            upper = spreads_of(loose, again[each, first, None], np.arange(ticks))[:, 0]
            wanted = bound <= np.maximum(upper[:, None], limit)
            wanted[each, first] = False
            found = spreads_of(loose, np.where(wanted, again, -1), np.arange(ticks))
            found[each, first] = upper
            # Held means within the allowance of the frame that holds it, and frames' allowances differ: a
            # chassis vertex on a front wheel's axle lies at the wheel's origin, so the wheel carries it a
            # float32 hair closer than the chassis does (1.6e-7 m against 2.0e-7) while only the chassis,
            # whose extent it is drawn from, allows that hair (the app precision measurement, FURY 2's
            # racecar, seed 10). A frame that holds it is chosen over one that comes closer but does not.
            ratio = found / limit
            pick = np.where(np.any(ratio <= 1, axis=1), np.argmin(ratio, axis=1), np.argmin(found, axis=1))
            best[loose] = again[each, pick]
            allowance = _allowance(vertices, pos, rot, best, tolerance)
            again_in(loose)

    choose_again(np.arange(n))
    welded = np.zeros(n, dtype=bool)
    if groups is not None and n and frames:
        before = best
        best, welded = _on_welded_shape(vertices[0], pos[0], rot[0], best, np.asarray(groups), centres, radii, outside)
        if welded.any():
            tied = tied & ~welded
            allowance = _allowance(vertices, pos, rot, best, tolerance)
            again_in(np.flatnonzero(best != before))
    if n and frames:
        moved = _with_the_majority(vertices, pos, rot, best, welded, allowance, error, tolerance, outside)
        if moved.any():
            tied = tied & ~moved
            allowance = _allowance(vertices, pos, rot, best, tolerance)
            again_in(np.flatnonzero(moved))
        # Moving vertices changes each frame's extent, so its allowance: a corner the world held by a hair when
        # it was chosen (brick 79's, a wrecking ball kicked: 1.05 of the world's allowance after the moves)
        # is chosen again; its brick held it to 1e-16 m (the app precision measurement, seed 6).
        choose_again(np.flatnonzero(~welded))
    reference = _centres(local, STILL * allowance)
    frame = np.where(best == frames, -1, best)
    return Attachment(frame=frame, error=error, allowance=allowance, reference=reference, tied=tied, welded=welded)


def _gaps(outside, vertices, pos, rot, rows, frames) -> np.ndarray:
    """How far vertex ``rows[i]`` lies outside the shapes of frame ``frames[i]`` (or of each ``frames[i, j]``)
    at the first tick: ``outside(frame, points in that frame)``, one call per frame."""
    gaps = np.zeros(frames.shape)
    for f in np.unique(frames):
        where = np.nonzero(frames == f)
        gaps[where] = outside(int(f), _transposed_times(rot[0, f], vertices[0, rows[where[0]]] - pos[0, f]))
    return gaps


def _with_the_majority(vertices, pos, rot, best, welded, allowance, error, tolerance, outside=None) -> np.ndarray:
    """Move to the frame most of the actor's vertices are held by every vertex that frame holds as well and
    that lies on no shape of its own frame (``best`` changed in place; which moved). A point on a joint's
    axis is held by both the link and its parent at every tick (a racecar's chassis vertex on a
    differential gear's axle): given to the gear by the nearest-frame search, it looked like a piece of
    the chassis drawn with the gear's pose. Welded frames' vertices keep the member whose shape they lie
    on, and so does a vertex on its own frame's shape and not on the majority's (two gears turning together)."""
    frames = pos.shape[1] - 1
    held = np.all(error <= allowance[:, None], axis=1)
    counts = np.bincount(best[held & (best < frames)], minlength=frames)
    if not counts.any():
        return np.zeros(len(best), dtype=bool)
    majority = int(np.argmax(counts))
    rows = np.flatnonzero(~welded & (best != majority) & (best < frames))
    if outside is not None and len(rows):
        # On its own frame's shape it stays, unless it lies on the majority's as well: a chassis vertex on the
        # differential's axle lies inside the side gear's collision shape too (the racecar with
        # URDF_MERGE_FIXED_LINKS, whose chassis is its base's; the zoo), and is the chassis's.
        own = _gaps(outside, vertices, pos, rot, rows, best[rows]) > ON_SHAPE
        shared = _gaps(outside, vertices, pos, rot, rows, np.full(len(rows), majority)) <= ON_SHAPE
        rows = rows[own | shared]
    if not len(rows):
        return np.zeros(len(best), dtype=bool)
    trial = best.copy()
    trial[rows] = majority
    room = _allowance(vertices, pos, rot, trial, tolerance)[rows]
    spread = np.max(_errors(_in_frames(vertices, pos, rot, trial, rows), STILL * room), axis=1)
    ok = spread <= room
    moved = np.zeros(len(best), dtype=bool)
    moved[rows[ok]] = True
    best[rows[ok]] = majority
    return moved


def _onto_a_shape(vertices, pos, rot, best, best_spread, allowance, outside, tolerance, near, spreads_of, stray) -> None:
    """Give each vertex the world holds, and each ``stray`` one (held by several frames, on none of their shapes),
    to a frame among its :data:`NEAREST` that holds it as well and whose shape it lies on (``best``, ``best_spread``
    changed in place); the :data:`FIRST` nearest by shape centre need not hold its own. The world holds whatever
    stood still during the probe ticks, with an allowance as wide as the world's drawing: a brick's corner, as
    near eight brick centres as its own brick's, had four other bricks as its nearest; they moved, the world
    took it and held it by a hair once its brick was kicked a little (0.994 of the allowance: the app precision
    measurement's wrecking ball, seed 6). A ball-pit floor's corner had two walls and two resting balls as its
    nearest, all still: it went to a wall it does not lie on, and was placed 2.3 m off that wall's centre (the
    ball pit, FURY 2, seed 9). A vertex on no shape (scenery, a floor drawn with no body) stays where it was."""
    frames = pos.shape[1] - 1
    rows = np.flatnonzero(((best == frames) | stray) & (best_spread <= allowance))
    if not len(rows):
        return
    candidates = near(rows)
    spreads = spreads_of(rows, candidates)
    spreads = np.where(_gaps(outside, vertices, pos, rot, rows, candidates) <= ON_SHAPE, spreads, np.inf)
    pick = np.argmin(spreads, axis=1)
    spread = spreads[np.arange(len(rows)), pick]
    chosen = candidates[np.arange(len(rows)), pick]
    found = np.isfinite(spread)  # on some body's shape, among the nearest
    rows, chosen, spread = rows[found], chosen[found], spread[found]
    trial = best.copy()
    trial[rows] = chosen
    ok = spread <= _allowance(vertices, pos, rot, trial, tolerance)[rows]
    best[rows[ok]] = chosen[ok]
    best_spread[rows[ok]] = spread[ok]


def _on_a_shape_first(vertices0, pos0, rot0, candidates, holding, closeness, outside, frames) -> np.ndarray:
    """``closeness`` with the frames a vertex lies on ranked first where several hold it (two gears turning
    together, a link and its parent on a still joint): how far outside each frame's shapes it lies
    (``outside``, to a tenth of a millimetre), then the centre over radius as before."""
    multi = np.flatnonzero(holding.sum(axis=1) >= 2)
    if not len(multi):
        return closeness
    gaps = np.full((len(multi), candidates.shape[1]), np.inf)
    for f in np.unique(candidates[multi][holding[multi]]):
        if f >= frames:
            continue  # the world: no shape; it holds what no body does
        rows, cols = np.nonzero((candidates[multi] == f) & holding[multi])
        local = _transposed_times(rot0[f], vertices0[multi[rows]] - pos0[f])
        gaps[rows, cols] = outside(int(f), local)
    closeness = closeness.copy()
    closeness[multi] = np.where(holding[multi], np.round(np.minimum(gaps, 1e3), 4) * 1e6 + np.minimum(closeness[multi], 1e5),
                                np.inf)
    return closeness


def _on_welded_shape(vertices0, pos0, rot0, best, groups, centres, radii, outside=None):
    """``best`` with each vertex held by a welded frame moved to the member of its group whose shape it
    lies on (closest to it by ``outside``, then closest to the shape's centre over its radius), and which
    vertices were welded."""
    frames = len(groups)
    in_group = (best < frames) & (groups[np.minimum(best, frames - 1)] >= 0)
    welded = np.zeros(len(best), dtype=bool)
    best = best.copy()
    for group in np.unique(groups[best[in_group]]):
        rows = np.flatnonzero(in_group & (groups[np.minimum(best, frames - 1)] == group))
        members = np.flatnonzero(groups == group)
        candidates = np.broadcast_to(members, (len(rows), len(members)))
        distance = _shape_distance(vertices0[rows], pos0, rot0, candidates, centres, radii)
        if outside is not None:
            # On a shape first (within a tenth of a millimetre); a vertex on several (where a leg meets the
            # body) goes with the member most of this actor's vertices lie on alone; else the most central.
            gaps = np.stack([outside(int(f), _transposed_times(rot0[f], vertices0[rows] - pos0[f])) for f in members], 1)
            on = gaps <= ON_SHAPE
            alone = on & (on.sum(axis=1, keepdims=True) == 1)
            votes = alone.sum(axis=0)
            distance = np.where(on, -votes[None, :] * 1e6 + np.minimum(distance, 1e5), 1e12 + gaps)
        best[rows] = members[np.argmin(distance, axis=1)]
        welded[rows] = True
    return best, welded


def _shape_distance(vertices0, pos0, rot0, candidates, centres, radii) -> np.ndarray:
    """``(n, k)``: each vertex's distance from each candidate frame's shape centre, over the shape's radius
    (below 1 on the shape); the world (the last frame) is farther than any body."""
    frames = pos0.shape[0] - 1
    c = np.concatenate([centres, np.zeros((1, 3))])[candidates]
    r = np.concatenate([radii, [1.0]])[candidates]
    local = _transposed_times(rot0[candidates], vertices0[:, None, :] - pos0[candidates])
    return np.where(candidates == frames, 1e30, np.linalg.norm(local - c, axis=-1) / r)


def _allowance(vertices, pos, rot, best, tolerance: Tolerance) -> np.ndarray:
    """Twice the kit's tolerance for each vertex, from the extent of the vertices its frame holds in
    this actor and the frame's largest distance from the origin."""
    return _twice(tolerance, _extents(vertices, pos, rot, best)[best], np.max(_lengths(pos), axis=0)[best])


def _allowances_in(vertices, pos, rot, best, candidates, tolerance: Tolerance) -> np.ndarray:
    """``(m, k)``: the allowance a vertex held by frame ``candidates[i, j]`` has, from the extent of the
    vertices that frame holds in this actor under ``best`` (not grown to reach the vertex: a far frame would
    allow a far vertex a wide miss, and take the wrong vertices of a lifted brick from their own)."""
    extent = _extents(vertices, pos, rot, best)[candidates]
    return _twice(tolerance, extent, np.max(_lengths(pos), axis=0)[candidates])


def _extents(vertices, pos, rot, best) -> np.ndarray:
    """``(F + 1,)``: how far from each frame's origin the vertices it holds (``best``) reach, at the first tick."""
    extent = np.zeros(pos.shape[1])
    np.maximum.at(extent, best, _lengths(_transposed_times(rot[0, best], vertices[0] - pos[0, best])))
    return extent


def _twice(tolerance: Tolerance, extent: np.ndarray, distance: np.ndarray) -> np.ndarray:
    """Twice the kit's tolerance for a vertex of a frame that reaches ``extent`` and strays ``distance`` from the origin."""
    return 2 * (tolerance.size_rtol * extent + tolerance.position_rtol * (distance + extent) + tolerance.atol)


# -- the usual mistakes, as frames ----------------------------------------------------------------

def _vtk_euler(quaternions: np.ndarray) -> np.ndarray:
    """What ``SetOrientation(*degrees(getEulerFromQuaternion(q)))`` draws (VTK turns about z, then x, then y)."""
    return poses.euler_matrices(quaternions, "ZXY", (2, 0, 1))


def rotations(quaternions: np.ndarray) -> np.ndarray:
    """The rotation matrices ``(..., 3, 3)`` of pyBullet's quaternions ``(..., 4)`` (x, y, z, w)."""
    return Rotation.from_quat(quaternions.reshape(-1, 4)).as_matrix().reshape(quaternions.shape[:-1] + (3, 3))


def _axis_angle(quaternions: np.ndarray, scale: float = 1.0) -> np.ndarray:
    """The rotations of the axis and angle of ``quaternions``, the angle times ``scale``."""
    q = Rotation.from_quat(quaternions.reshape(-1, 4))
    return Rotation.from_rotvec(q.as_rotvec() * scale).as_matrix().reshape(quaternions.shape[:-1] + (3, 3))


def _euler_as_degrees(quaternions: np.ndarray) -> np.ndarray:
    """The rotations pyBullet's Euler angles of ``quaternions`` (R = Rz(yaw)·Ry(pitch)·Rx(roll): scipy's 'xyz')
    give when they are read as degrees. The angles are pyBullet's own (``getEulerFromQuaternion``): at a pitch
    of ±90° it splits the turn between roll and yaw otherwise than scipy's ``as_euler`` (the kit's perturbed
    runs turn bodies there), and the shrunk turns differ."""
    shrunk = Rotation.from_euler("xyz", pybullet_euler(quaternions.reshape(-1, 4)), degrees=True)
    return shrunk.as_matrix().reshape(quaternions.shape[:-1] + (3, 3))


def pybullet_euler(quaternions: np.ndarray) -> np.ndarray:
    """``(n, 3)``: what pyBullet's ``getEulerFromQuaternion`` gives for each of ``quaternions`` ``(n, 4)``, its
    formula in numpy (pybullet.c; equal to it to 1e-15 rad over 20,000 random turns and 200 at and near a pitch of
    ±90°, where it puts the whole turn in the yaw)."""
    x, y, z, w = quaternions.T
    sarg = -2 * (x * z - w * y)
    roll = np.arctan2(2 * (y * z + w * x), w * w - x * x - y * y + z * z)
    pitch = np.arcsin(np.clip(sarg, -1, 1))
    yaw = np.arctan2(2 * (x * y + w * z), w * w + x * x - y * y - z * z)
    low, high = sarg <= -0.99999, sarg >= 0.99999
    roll = np.where(low | high, 0.0, roll)
    pitch = np.where(low, -0.5 * np.pi, np.where(high, 0.5 * np.pi, pitch))
    yaw = np.where(low, 2 * np.arctan2(x, -y), np.where(high, 2 * np.arctan2(-x, y), yaw))
    return np.stack([roll, pitch, yaw], axis=1)


def _float32_axis_angle(quaternions: np.ndarray) -> np.ndarray:
    """What pyBullet's ``getAxisAngleFromQuaternion`` gives, as rotations: Bullet's btQuaternion getAngle and
    getAxis in float32 (the angle ``2 acos(w)``, so 0.001 rad comes back as 0.0009765625; the axis (1, 0, 0)
    where ``1 - w²`` is under ten float32 epsilons, angles below about 0.002 rad). Measured against pybullet
    3.2.7: the axis exactly, the angle to 1-2 float32 ulps (4.8e-7 rad at most over 500 random turns)."""
    q = quaternions.reshape(-1, 4).astype(np.float32)
    w = np.minimum(np.abs(q[:, 3]), np.float32(1)) * np.sign(q[:, 3] + (q[:, 3] == 0))
    angle = (np.float32(2) * np.arccos(w)).astype(np.float32)
    s2 = (np.float32(1) - w * w).astype(np.float32)
    small = s2 < np.float32(10) * np.finfo(np.float32).eps
    axis = np.where(small[:, None], np.array([1, 0, 0], np.float32),
                    q[:, :3] / np.sqrt(np.where(small, np.float32(1), s2))[:, None]).astype(np.float32)
    rotvec = axis.astype(np.float64) * angle.astype(np.float64)[:, None]
    return Rotation.from_rotvec(rotvec).as_matrix().reshape(quaternions.shape[:-1] + (3, 3))


#: name → (what it means, function of (positions, quaternions, before_positions, before_quaternions)
#: giving the frame positions and rotation matrices that mistake draws with)
VARIANTS = {
    "previous-step": ("drawn exactly at pyBullet's pose of the previous step (or of the previous tick, where a tick "
                      "steps several times): sync after p.stepSimulation(), and read links with getLinkState(..., "
                      "computeForwardKinematics=1)",
                      lambda p, q, bp, bq: (bp, rotations(bq))),
    "conjugate": ("drawn with the inverse (conjugate, or transposed-matrix) rotation: a row-vector `v @ R` where "
                  "`R @ v` was meant, or a matrix written transposed",
                  lambda p, q, bp, bq: (p, np.swapaxes(rotations(q), -1, -2))),
    "wxyz": ("drawn with the quaternion reordered to (w, x, y, z) and handed to something that takes pyBullet's "
             "(x, y, z, w): scipy's Rotation.from_quat (unless scalar_first=True), pygfx's local.rotation, pyBullet's "
             "own calls: pass pyBullet's quaternion as it is",
             lambda p, q, bp, bq: (p, rotations(np.roll(q, 1, axis=-1)))),
    "scalar-first": ("drawn with pyBullet's (x, y, z, w) quaternion read as (w, x, y, z) (scalar first: transforms3d, "
                     "Eigen, scipy's scalar_first=True): read it as (x, y, z, w)",
                     lambda p, q, bp, bq: (p, rotations(np.roll(q, -1, axis=-1)))),
    "euler-order": ("drawn with pyBullet's Euler angles applied in VTK's order (SetOrientation turns about z, then x, "
                    "then y; getEulerFromQuaternion's angles are about fixed x, y, z): set a matrix from the quaternion",
                    lambda p, q, bp, bq: (p, _vtk_euler(q))),
    "translation-only": ("moved but never turned: the position is pyBullet's, the rotation the one it was built with",
                         lambda p, q, bp, bq: (p, np.broadcast_to(np.eye(3), p.shape[:-1] + (3, 3)))),
    "radians-as-degrees": ("turned by angles in radians where degrees are taken: VTK's RotateWXYZ(angle, x, y, z), "
                           "SetOrientation and RotateX/Y/Z, scipy's from_euler(..., degrees=True) and "
                           "from_rotvec(..., degrees=True) take degrees: give math.degrees(angle), or build the "
                           "rotation from the quaternion",
                           lambda p, q, bp, bq: (p, _axis_angle(q, np.pi / 180))),
    # The same mistake made on pyBullet's Euler angles (scipy's from_euler('xyz', getEulerFromQuaternion(q),
    # degrees=True)): each angle shrunk, not the turn's one angle, which parts from the above past small turns.
    "radians-as-degrees, Euler": ("", lambda p, q, bp, bq: (p, _euler_as_degrees(q))),
    # A visual shape's frame composed the wrong way round with its link's (visual @ link): it depends on each
    # frame's visual frame, which these poses do not hold, so the judgement makes it (naming.Naming._variants); here
    # the link's own pose stands in, which explains nothing.
    "visual-frame, order": ("", lambda p, q, bp, bq: (p, rotations(q))),
    # Drawn a tick late where a tick steps several times (the pose at the end of the previous tick, before the
    # tick's first step): made by the judgement from the recording's ticks (naming.Naming._variants), as above.
    "previous-step, tick": ("", lambda p, q, bp, bq: (p, rotations(q))),
    "float32-angle-axis": ("turned by pyBullet's getAxisAngleFromQuaternion, which computes in float32: an angle of "
                           "0.001 rad comes back as 0.0009765625, and below about 0.002 rad the axis is (1, 0, 0): "
                           "build the rotation from the quaternion (getMatrixFromQuaternion, scipy's Rotation.from_quat)",
                           lambda p, q, bp, bq: (p, _float32_axis_angle(q))),
}


#: Variants that are another form of a mistake named before them: the name a diagnosis gives them.
#: The variants that differ from pyBullet's pose by the rotation alone: more than one of them can hold one
#: drawing (:meth:`conformance.apps.naming.Naming._turn_on_its_shape` tells them apart)
TURNS = ("conjugate", "wxyz", "scalar-first", "euler-order", "translation-only", "radians-as-degrees",
         "radians-as-degrees, Euler", "float32-angle-axis")

ALIASES = {"radians-as-degrees, Euler": "radians-as-degrees", "visual-frame, order": "visual-frame",
           "previous-step, tick": "previous-step"}


def visual_order(positions: np.ndarray, rotations: np.ndarray, frames) -> tuple[np.ndarray, np.ndarray]:
    """Each frame's pose ``(T, F, 3)``, ``(T, F, 3, 3)`` as a drawing shows it whose one visual frame is
    composed the wrong way round with the link's (:func:`visual_order_of`). A frame with no visual frame, or
    several different ones, keeps its own pose (the judge tries those one by one, :func:`visual_frames`)."""
    positions, rotations = np.array(positions, dtype=np.float64), np.array(rotations, dtype=np.float64)
    for index, frame in enumerate(frames):
        placed = visual_frames(frame)
        if len(placed) != 1:
            continue
        positions[:, index], rotations[:, index] = visual_order_of(positions[:, index], rotations[:, index], *placed[0])
    return positions, rotations


def visual_frames(frame) -> list[tuple[np.ndarray, np.ndarray]]:
    """The distinct visual frames ``(p_v, q_v)`` of a frame's visual shapes that are not the identity."""
    placed = {(tuple(np.round(v[2], 9)), tuple(np.round(v[3], 9))) for v in getattr(frame, "visuals", ())}
    found = []
    for p_v, q_v in sorted(placed):
        p_v, q_v = np.asarray(p_v, dtype=np.float64), np.asarray(q_v, dtype=np.float64)
        if np.linalg.norm(p_v) >= 1e-9 or abs(abs(q_v[3]) - 1) > 1e-9:
            found.append((p_v, q_v))
    return found


def visual_order_of(positions: np.ndarray, rotations: np.ndarray, p_v, q_v) -> tuple[np.ndarray, np.ndarray]:
    """One frame's pose ``(T, 3)``, ``(T, 3, 3)`` as a drawing shows it whose visual frame ``(p_v, q_v)`` is
    composed the wrong way round with the link's ``(p, R)`` (visual @ link where link @ visual is meant): a point
    at ``x`` in the link frame is drawn at ``R_v R R_vᵀ (x - p_v) + p_v + R_v p``."""
    r_v = Rotation.from_quat(q_v).as_matrix()
    turned = np.einsum("ij,tjk,lk->til", r_v, rotations, r_v)
    return p_v + positions @ r_v.T - turned @ p_v, turned


def variant_fit(vertices: np.ndarray, positions: np.ndarray, rotations: np.ndarray, reference: np.ndarray,
                allowance: np.ndarray, ticks: np.ndarray) -> bool:
    """Whether the vertices ``(T, m, 3)`` sit at ``reference`` (or at one fixed place of their own; only
    there when ``reference`` is None) in the frames ``(T, m, 3)``/``(T, m, 3, 3)`` at every tick of ``ticks``
    (indices), within ``allowance``."""
    # Each vertex passes or fails on its own, so one vertex that fits neither place rules the variant out at
    # the cost of one vertex: most variants tried on a wrong drawing fail so (a third of judging a robot
    # drawn with degrees for radians).
    one = slice(0, 1)
    first = local_coordinates(vertices[ticks, one], positions[ticks, one], rotations[ticks, one])
    own = np.median(local_coordinates(vertices[:, one], positions[:, one], rotations[:, one]), axis=0)
    candidates = ((None, own),) if reference is None else ((reference, reference[one]), (None, own))
    places = [ref for ref, at in candidates
              if np.all(np.linalg.norm(first - at, axis=-1) <= allowance[one])]
    if not places:
        return False
    local = local_coordinates(vertices[ticks], positions[ticks], rotations[ticks])
    for ref in places:
        if ref is None:
            ref = np.median(local_coordinates(vertices, positions, rotations), axis=0)
        if np.all(np.linalg.norm(local - ref, axis=-1) <= allowance):
            return True
    return False


def bad_ticks(error: np.ndarray, allowance: np.ndarray) -> np.ndarray:
    """The ticks (indices) at which some vertex's error ``(m, T)`` is beyond its allowance ``(m,)``."""
    return np.flatnonzero(np.any(error > allowance[:, None], axis=0))


def runs(mask: np.ndarray, frames: np.ndarray):
    """``(start, stop)`` of each run of consecutive true entries of ``mask`` with one frame."""
    start = None
    for i in range(len(mask) + 1):
        boundary = i == len(mask) or not mask[i] or (start is not None and frames[i] != frames[start])
        if start is not None and boundary:
            yield start, i
            start = None
        if i < len(mask) and mask[i] and start is None:
            start = i
