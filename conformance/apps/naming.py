"""How a drawing that is not where pyBullet holds it was drawn wrong: the mistake of the catalogue
(:data:`conformance.apps.attachment.VARIANTS`) under which its frame holds it, the frame it was meant to follow,
and the evidence that tells two mistakes apart where both hold it (a rotation mistake under which the drawing lies
on its frame's shapes; a pose before the app's own moves against one a step late; a drawing that lies on another
frame's shapes, paired with the wrong body).

:class:`Naming` is the part of :class:`conformance.apps.judge._Judgement` that names mistakes; the checks there
say what failed, this says why. It reads the judgement's recording and frame poses (``r``, ``pos``, ``orn``,
``rot``, ``tolerance``) and its ``_errors``, ``_outside``, ``_radii`` and ``_with_world``.
"""

from __future__ import annotations

import functools

import numpy as np

from conformance.apps import attachment as attach_mod
from conformance.apps.placement import bounding_radius, candidates

__all__ = ["Naming", "UNTOUCHED_ATOL"]

#: A write that changes a pose or velocity by no more than this is no change (resetting a body to the
#: pose just read may round its last bit).
UNTOUCHED_ATOL = 1e-12
#: :meth:`Naming._owners`' mistake index of the pose before the app's own moves: one past the catalogue
_OWN_MOVE = len(attach_mod.VARIANTS) + 1
#: Of two rotation mistakes that hold a drawing alike, the one made is the one under which the drawing lies on its
#: frame's shapes (its vertices on average within this share of its reach of them) while under every other it
#: lies off them (past the second share): the other puts the shape flipped, a link's length off its origin
#: (cartpole's pole, 0.5 m; half_cheetah's thighs). A visual mesh is judged by shapes that only approximate it,
#: so between the two nothing is named.
ON_ITS_SHAPE, OFF_ITS_SHAPE = 0.05, 0.25
#: A drawing lies on a frame's shapes when its vertices are within this share of its own reach of them, on
#: average (:meth:`Naming._on_another_frame`)
ON_SHAPE = 0.25
#: ... and is that frame's shape when its extents are within this share of the shape's largest of its extents
OF_ITS_SIZE = 0.1


def _own_place(vertices: np.ndarray, positions: np.ndarray, rotations: np.ndarray) -> np.ndarray:
    """The median place ``(m, 3)`` of vertices ``(T, m, 3)`` in a frame posed by ``positions``, ``rotations``."""
    return np.median(attach_mod.local_coordinates(vertices, positions, rotations), axis=0)


def _of_a_size(points: np.ndarray, shapes: list) -> bool:
    """Whether the box of ``points`` (in the axes of the frame that carries them) has the extents of one of
    ``shapes`` (another frame's :func:`~conformance.apps.placement.candidates`), in any order of its axes."""
    half = np.sort((points.max(axis=0) - points.min(axis=0)) / 2)
    return any(np.all(np.abs(half - np.sort(h)) <= OF_ITS_SIZE * float(np.max(h)) + 1e-9) for _, _, _, h in shapes)


class Naming:
    """The mistake-naming half of the app judgement (see the module's docstring)."""

    @functools.cached_property
    def _variants(self) -> list[tuple[np.ndarray, np.ndarray]]:
        """Every frame's positions ``(T, F, 3)`` and rotations ``(T, F, 3, 3)`` under each mistake of the
        catalogue (:data:`~conformance.apps.attachment.VARIANTS`, in its order): computed once for all frames,
        not once for each loose piece and frame (a wrong 100-brick wall's diagnosis spent most of its time there)."""
        before_pos, before_orn = self.r.before_positions[1:], self.r.before_orientations[1:]
        made = [tuple(np.asarray(a) for a in make(self.pos, self.orn, before_pos, before_orn))
                for _, make in attach_mod.VARIANTS.values()]
        # The one mistake whose pose depends on each frame's shapes, not on its pose alone
        made[list(attach_mod.VARIANTS).index("visual-frame, order")] = attach_mod.visual_order(
            self.pos, self.rot, self.r.frames)
        made[list(attach_mod.VARIANTS).index("previous-step, tick")] = (
            self.r.positions[:-1], attach_mod.rotations(self.r.orientations[:-1]))
        return made

    @functools.cached_property
    def _variant_stack(self) -> tuple[np.ndarray, np.ndarray]:
        """:attr:`_variants` stacked: positions ``(V, T, F, 3)`` and rotations ``(V, T, F, 3, 3)``."""
        shape = self.pos.shape
        return (np.stack([np.broadcast_to(p, shape) for p, _ in self._variants]),
                np.stack([np.broadcast_to(r, shape + (3,)) for _, r in self._variants]))

    def _variants_possible(self, vertices, frame, reference, allowance, bad_ticks) -> np.ndarray:
        """``(V,)``: whether each variant could hold the vertices, judged by the first one alone under every
        variant at once (the test :func:`~conformance.apps.attachment.variant_fit` makes, with a hair of
        slack): a loose piece's diagnosis tried the catalogue variant by variant, most of judging a robot
        drawn with degrees for radians."""
        if not vertices.shape[1] or not len(bad_ticks):
            return np.ones(len(self._variants), dtype=bool)
        pos, rot = self._variant_stack
        local = np.einsum("vtji,vtj->vti", rot[:, :, frame], vertices[None, :, 0] - pos[:, :, frame])
        limit = allowance[0] * (1 + 1e-9)
        at_reference = np.all(np.linalg.norm(local[:, bad_ticks] - reference[0], axis=-1) <= limit, axis=1)
        own = np.median(local, axis=1)
        at_own = np.all(np.linalg.norm(local[:, bad_ticks] - own[:, None], axis=-1) <= limit, axis=1)
        return at_reference | at_own

    def _loose_pieces(self, track, a, loose):
        """``(start, stop, frame, diagnosis)`` of the actor's loose vertices, one per body or link they were
        meant to follow (one shared actor draws many): each vertex goes to the nearby frame that holds it
        under a known mistake (or, when none does, that it follows best), and consecutive vertices with the
        same frame and mistake make one piece."""
        pieces = []
        late = list(attach_mod.VARIANTS).index("previous-step") + 1

        def add(piece, frame, diagnosis):
            if pieces and pieces[-1][1] == piece[0] and pieces[-1][2:] == (frame, diagnosis):
                pieces[-1] = (pieces[-1][0], int(piece[-1]) + 1, frame, diagnosis)
            else:
                pieces.append((int(piece[0]), int(piece[-1]) + 1, frame, diagnosis))

        for start, stop in attach_mod.runs(loose, np.zeros(len(loose), dtype=int)):
            rows = np.arange(start, stop)
            frames, mistakes = self._owners(track.vertices[1:, rows], a.frame[rows], a.allowance[rows])
            # Where a joint reset barely moved a link, the poses before the step and before the app's own
            # moves both hold its vertices, and each vertex went to the nearer by a hair: a mini cheetah's thigh
            # in 377 runs of the two. Told on the whole run; where that names nothing, run by run as found.
            merged = np.where(mistakes == late, _OWN_MOVE, mistakes)
            for s, e in attach_mod.runs(np.ones(len(rows), dtype=bool), frames * (_OWN_MOVE + 1) + merged):
                piece, frame = rows[s:e], int(frames[s])
                if set(mistakes[s:e].tolist()) == {late, _OWN_MOVE}:
                    diagnosis = self._own_move_of(track, a, piece, frame)
                    if diagnosis:
                        add(piece, frame, diagnosis)
                        continue
                for s2, e2 in attach_mod.runs(np.ones(e - s, dtype=bool), mistakes[s:e]):
                    add(piece[s2:e2], *self._piece(track, a, piece[s2:e2], frame, int(mistakes[s + s2])))
        return pieces

    def _own_move_of(self, track, a, piece, frame: int) -> str:
        """:meth:`_later_than_the_step` of a piece :meth:`_owners` gave to ``frame``, which may not be the one the
        attachment found for it: the reference is where the drawing sits in that one, of no use in another."""
        reference = a.reference[piece] if np.all(a.frame[piece] == frame) else None
        return self._later_than_the_step(track.vertices[1:, piece], frame, reference)

    def _piece(self, track, a, piece, frame: int, mistake: int) -> tuple[int, str]:
        """The frame and diagnosis of a run of loose vertices that :meth:`_owners` gave to ``frame`` under
        ``mistake`` (0 none, :data:`_OWN_MOVE` the pose before the app's own moves)."""
        vertices = track.vertices[1:, piece]
        if mistake == _OWN_MOVE:
            diagnosis = self._own_move_of(track, a, piece, frame)
            return (frame, diagnosis) if diagnosis else self._followed(vertices, a.frame[piece], a.reference[piece])
        if mistake:
            diagnosis = list(attach_mod.VARIANTS)[mistake - 1]
            if diagnosis in attach_mod.TURNS:  # the first that holds it; a later one may hold it alike
                return frame, self._turn_on_its_shape(frame, self._turns_holding(vertices, frame, diagnosis))
            diagnosis = attach_mod.ALIASES.get(diagnosis, diagnosis)
            if diagnosis == "previous-step":  # or later than the step: before the app's own moves
                diagnosis = self._later_than_the_step(vertices, frame, a.reference[piece]) or diagnosis
            return frame, diagnosis
        return self._followed(vertices, a.frame[piece], a.reference[piece])

    def _owners(self, vertices, best, allowance) -> tuple[np.ndarray, np.ndarray]:
        """Per loose vertex ``(T, m, 3)``: the frame index it belongs to and the mistake (1-based index into
        the catalogue, 0 none, one past the catalogue the pose before the app's own moves) under which that
        frame holds it. Candidates are the frames near it at tick 1 (within twice their shape's radius) and
        the frame that came nearest to holding it."""
        m = vertices.shape[1]
        frames = np.where(best >= 0, best, 0).astype(int)
        mistakes = np.zeros(m, dtype=int)
        if not self.r.frames:
            return frames, mistakes
        radius = self._radii
        distance = np.linalg.norm(vertices[0][:, None, :] - self.pos[0][None, :, :], axis=-1)  # (m, F)
        near = distance <= 2 * radius[None, :] + 1e-9
        near[np.arange(m)[best >= 0], best[best >= 0]] = True
        score = np.full(m, np.inf)
        ticks = len(vertices)
        probes = np.unique(np.linspace(0, ticks - 1, 4).astype(int)) if ticks else np.arange(0)
        # A drawing at the pose before the app's own moves (a playback drawn before its resetJointState) is
        # found here in runs of its frames; left to _followed, it fell apart into thousands of pieces, each
        # diagnosed on its own (36 s of a Franka playback's judgement). A robot's visual meshes reach past its
        # collision shapes and its link origins crowd at the joints, so no nearness finds a vertex's frame:
        # under this pose every frame the app moved is a candidate (a probe of 4 ticks rules most out).
        before = self._poses_before_writes
        near_own = np.zeros_like(near)
        if before is not None:
            near_own[:] = before[2].any(axis=0)[None, :]
        for f in np.flatnonzero(near.any(axis=0) | near_own.any(axis=0)):
            poses = list(self._variants) + ([before[:2]] if near_own[:, f].any() else [])
            for k, (positions, rotations) in enumerate(poses, start=1):
                near_f = np.flatnonzero(near_own[:, f] if k == _OWN_MOVE else near[:, f])
                if not len(near_f):
                    continue
                # Held within the allowance of one place at every tick means within twice it of the first
                # tick's place at a few: a necessary test on 4 ticks of 40 rules most pairs out (exact).
                probed = attach_mod.in_frame(vertices[probes][:, near_f], positions[probes, f], rotations[probes, f])
                spread = np.max(np.linalg.norm(probed - probed[:1], axis=-1), axis=0, initial=0)
                rows = near_f[spread <= 2 * allowance[near_f] * (1 + 1e-9)]
                if not len(rows):
                    continue
                local = attach_mod.in_frame(vertices[:, rows], positions[:, f], rotations[:, f])
                error = attach_mod._errors(local).max(axis=1) / allowance[rows]
                better = (error <= 1.0) & (error < score[rows])
                frames[rows[better]], mistakes[rows[better]], score[rows[better]] = f, k, error[better]
        return frames, mistakes

    def _followed(self, vertices, best, reference) -> tuple[int, str]:
        """The frame a run of loose vertices follows, and the mistake that explains it if one does: of
        the frames its vertices came nearest to being held by and the four frames nearest to the run,
        the first whose pose under a known mistake holds the run; else the one with the smallest median
        error (the world only when no body does better)."""
        centre = vertices[0].mean(axis=0)
        nearest = np.argsort(np.linalg.norm(self.pos[0] - centre, axis=1))[:4] if self.pos.shape[1] else []
        candidates = list(dict.fromkeys([int(f) for f in np.unique(best) if f >= 0] + [int(f) for f in nearest]))
        scored = []
        for frame in candidates:
            error, allowance = self._errors(vertices, frame)
            bad_ticks = attach_mod.bad_ticks(error, allowance)
            diagnosis = self._diagnose(vertices, frame, reference, allowance, bad_ticks)
            if diagnosis:
                return frame, diagnosis
            scored.append((float(np.median(error)), frame))
        world, _ = self._errors(vertices, -1)
        scored.append((float(np.median(world)) + 1e-12, -1))
        return min(scored)[1], ""

    def _diagnose(self, vertices, frame, reference, allowance, bad_ticks) -> str:
        if frame < 0:
            return ""
        own = self._before_own_move(vertices, frame, reference, allowance, bad_ticks)
        if own:
            return own
        possible = self._variants_possible(vertices, frame, reference, allowance, bad_ticks)
        turns = []  # the rotation mistakes that hold the vertices: (name, their own place in that frame)
        for name, (positions, rotations), could in zip(attach_mod.VARIANTS, self._variants, possible):
            if not could or (turns and name not in attach_mod.TURNS):
                continue
            positions, rotations = positions[:, frame, None], rotations[:, frame, None]
            if attach_mod.variant_fit(vertices, positions, rotations, reference, allowance, bad_ticks):
                # A late sync is late wherever the body moved; drawn right at some of those ticks, it skipped
                if name == "previous-step" and not attach_mod.variant_fit(
                        vertices, positions, rotations, reference, allowance, np.arange(len(vertices))):
                    return "skipped"
                if name not in attach_mod.TURNS:
                    return attach_mod.ALIASES.get(name, name)
                turns.append((attach_mod.ALIASES.get(name, name),
                              _own_place(vertices, positions, rotations)))
        if turns:
            return self._turn_on_its_shape(frame, turns)
        if self._visual_order_fits(vertices, frame, reference, allowance, bad_ticks):
            return "visual-frame"
        return "skipped" if self._skipped(vertices, frame, allowance) else ""

    def _turns_holding(self, vertices, frame: int, first: str) -> list:
        """``(name, own place)`` of the rotation mistakes from ``first`` on (a key of the catalogue, which holds
        ``vertices``) that hold them in ``frame``, each at one fixed place of its own at every tick."""
        _, allowance = self._errors(vertices, frame)
        ticks = np.arange(len(vertices))
        found = []
        for name, (positions, rotations) in list(zip(attach_mod.VARIANTS, self._variants))[list(attach_mod.VARIANTS).index(first):]:
            if name not in attach_mod.TURNS:
                continue
            positions, rotations = positions[:, frame, None], rotations[:, frame, None]
            if name == first or attach_mod.variant_fit(vertices, positions, rotations, None, allowance, ticks):
                found.append((attach_mod.ALIASES.get(name, name),
                              _own_place(vertices, positions, rotations)))
        return found

    def _turn_on_its_shape(self, frame: int, turns: list) -> str:
        """Which of several rotation mistakes that each hold a drawing made it: the one under which the drawing
        lies on its frame's shapes. Two can hold it alike: a link turning about the world's y axis drawn with
        its quaternion reordered (w, x, y, z) is drawn as by the inverse rotation of its shape flipped about its
        x axis, at every tick (R(wxyz of q) = R(q)ᵀ·Rx(π)), so only where the shape lies tells them apart. ""
        when none or several lie on it (a shape the flip leaves as it was): either could be meant."""
        if len(turns) == 1:
            return turns[0][0]
        own = turns[0][1]
        if len(own) < 4:  # a few vertices of a drawing lie on a shape, or off it, whichever way it is turned
            return ""
        reach = max(float(np.max(np.linalg.norm(own - own.mean(axis=0), axis=1))), 1e-9)  # a turn keeps it
        outside = np.array([float(np.mean(self._outside(frame, place))) for _, place in turns]) / reach
        on, off = outside <= ON_ITS_SHAPE, outside > OFF_ITS_SHAPE
        return turns[int(np.argmin(outside))][0] if on.sum() == 1 and off.sum() == len(turns) - 1 else ""

    def _visual_order_fits(self, vertices, frame, reference, allowance, bad_ticks) -> bool:
        """Whether one of the frame's several visual frames, composed the wrong way round with its pose, holds
        the vertices: one actor per visual shape posed by ``visual @ link`` (the catalogue's variant covers a
        frame with one visual frame; a robot's link often has several)."""
        placed = attach_mod.visual_frames(self.r.frames[frame]) if frame < len(self.r.frames) else []
        if len(placed) < 2:
            return False
        for p_v, q_v in placed:
            positions, rotations = attach_mod.visual_order_of(self.pos[:, frame], self.rot[:, frame], p_v, q_v)
            if attach_mod.variant_fit(vertices, positions[:, None], rotations[:, None], reference, allowance, bad_ticks):
                return True
        return False

    @functools.cached_property
    def _poses_before_writes(self) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """Each frame's pose after the tick's last step and before the app's own first write of the tick
        (positions ``(T, F, 3)``, rotations ``(T, F, 3, 3)``), the pose it drew at ticks without a write that
        moved it; and ``(T, F)`` where a write moved it. None when the app moved nothing after its steps."""
        writes = self.r.writes
        if writes is None or not len(self.pos):
            return None
        before = writes[1:len(self.pos) + 1, :, :7]
        known = np.isfinite(before).all(axis=-1)
        held = np.where(known[..., None], before, np.concatenate([self.pos, self.orn], axis=-1))
        # A joint reset may turn a link about its own origin: moved is moved or turned.
        turned = 1 - np.abs(np.sum(held[..., 3:7] * self.orn, axis=-1)) > 1e-12
        moved = known & ((np.linalg.norm(self.pos - held[..., :3], axis=-1) > UNTOUCHED_ATOL) | turned)
        if not moved.any():
            return None
        positions = np.where(moved[..., None], held[..., :3], self.pos)
        rotations = np.where(moved[..., None, None], attach_mod.rotations(np.where(moved[..., None], held[..., 3:7], self.orn)),
                             self.rot)
        return positions, rotations, moved

    def _before_own_move(self, vertices, frame, reference, allowance, bad_ticks) -> str:
        """``"before-own-move"`` when the vertices sit, at the failing ticks, where the frame was after the step
        and before the app's own moves of that tick (``resetJointState`` of a playback), and not at its pose
        before the step: the sync ran between them. Where both poses hold them (a step that moves a kinematic
        arm less than the allowance: after ``resetJointState`` a step leaves its joints exactly where they
        were, measured) this run cannot tell the two mistakes apart: ``"late-or-own-move"``, which
        :mod:`~conformance.apps.told_apart` settles with a run of its own."""
        before = self._poses_before_writes
        if before is None or not before[2][:, frame].any() or not len(bad_ticks):
            return ""
        positions, rotations, _ = before
        positions, rotations = positions[:, frame, None], rotations[:, frame, None]
        if not attach_mod.variant_fit(vertices, positions, rotations, reference, allowance, bad_ticks):
            return ""
        late = list(attach_mod.VARIANTS).index("previous-step")
        late_pos, late_rot = (a[:, frame, None] for a in self._variants[late])
        if not attach_mod.variant_fit(vertices, late_pos, late_rot, reference, allowance, bad_ticks):
            return "before-own-move"
        own = attach_mod.local_coordinates(vertices[bad_ticks], positions[bad_ticks], rotations[bad_ticks])
        behind = attach_mod.local_coordinates(vertices[bad_ticks], late_pos[bad_ticks], late_rot[bad_ticks])
        apart = float(np.max(np.linalg.norm(own - behind, axis=-1), initial=0.0))
        limit = float(np.max(allowance))
        if apart > limit and reference is not None:
            # Each pose holds the drawing at a place of its own: the drawing's place in the frame says which,
            # where it is one of them. Read from a drawing wrong at every tick it is neither (a median of
            # wrong places), and then this run cannot tell, as when the two places are one.
            own_off, behind_off = (float(np.max(np.linalg.norm(local - reference, axis=-1))) for local in (own, behind))
            if min(own_off, behind_off) <= limit:
                return "before-own-move" if own_off < behind_off else ""
        # A late sync is late wherever the body moved; drawn right at some of those ticks, it skipped
        if not attach_mod.variant_fit(vertices, positions, rotations, reference, allowance, np.arange(len(vertices))):
            return "skipped"
        return "late-or-own-move"

    def _later_than_the_step(self, vertices, frame, reference) -> str:
        """:meth:`_before_own_move` for a piece :meth:`_owners` found a step late or before the app's own moves
        (``reference`` None when the frame is not the one the attachment found for it)."""
        error, allowance = self._errors(vertices, frame)
        bad_ticks = attach_mod.bad_ticks(error, allowance)
        return self._before_own_move(vertices, frame, reference, allowance, bad_ticks)

    def _skipped(self, vertices, f, allowance) -> bool:
        """Whether at every tick the vertices sit, in their frame, where they sat at one of the first ticks,
        under pyBullet's pose of that tick or of the one before it, and under the one before at some tick:
        a sync that runs every other tick, or skips a body now and then, while the body moves (the median
        reference of half-wrong ticks fits neither pose, so the variants above cannot see it)."""
        ticks = len(vertices)
        if ticks < 3:
            return False
        turns = attach_mod.rotations(self.r.before_orientations[1:][:, f])
        # Every vertex must sit so at every tick: one that does not at some tick, under every first tick,
        # rules the piece out at the cost of one vertex (most pieces of a wrong drawing).
        if vertices.shape[1]:
            one = vertices[:, :1]
            now, before = (attach_mod.in_frame(one, self.pos[:, f], self.rot[:, f]),
                           attach_mod.in_frame(one, self.r.before_positions[1:][:, f], turns))
            if not any(np.all((np.linalg.norm(now - now[first], axis=-1) <= allowance[:1])
                              | (np.linalg.norm(before - now[first], axis=-1) <= allowance[:1]))
                       for first in range(min(3, ticks))):
                return False
        now = attach_mod.in_frame(vertices, self.pos[:, f], self.rot[:, f])
        before = attach_mod.in_frame(vertices, self.r.before_positions[1:][:, f], turns)
        for first in range(min(3, ticks)):
            right = np.all(np.linalg.norm(now - now[first], axis=-1) <= allowance, axis=1)
            late = np.all(np.linalg.norm(before - now[first], axis=-1) <= allowance, axis=1)
            if np.all(right | late) and np.any(late & ~right) and np.any(right[1:] & ~late[1:]):
                return True
        return False

    def _on_another_frame(self, track, rows, frame: int) -> bool:
        """Whether the part of the drawing of ``rows`` (held by ``frame``) that lies off ``frame``'s shapes at the
        first tick lies on another frame's shapes instead, its centre in them: the evidence that it was paired
        with another body (a range counted wrong draws one body's shape at the other's place where it was
        built, then carries it with the wrong pose), and has the size of one of them in the axes of the frame that
        carries it (the wrong body's actor is built in its own axes and posed as a whole): it is that shape. A
        drawing far from its shape for another reason (a scale applied twice, a frame composed wrong, a gripper's
        base turned onto its fingers) lies on none, is centred on its own, or is not the size of what it lies on."""
        def local(points, f):
            return attach_mod.in_frame(points[None], self.pos[:1, f], self.rot[:1, f])[0]

        def reach(points):
            return max(float(np.max(np.linalg.norm(points - points.mean(axis=0), axis=1))), 1e-9)

        points = track.vertices[1, rows]
        off = points[self._outside(frame, local(points, frame)) > ON_SHAPE * reach(points)]
        if not len(off):
            return False
        centre, slack = off.mean(axis=0, keepdims=True), ON_SHAPE * reach(off)
        if float(self._outside(frame, local(centre, frame))[0]) <= slack:
            return False
        for other, info in enumerate(self.r.frames):
            if other == frame or info.node >= 0 or not (info.shapes or info.visuals):
                continue
            if float(self._outside(other, local(centre, other))[0]) <= slack and \
                    float(np.mean(self._outside(other, local(off, other)))) <= slack and \
                    _of_a_size(local(off, frame), candidates(info.shapes, info.mesh, info.visuals)):
                return True
        return False

    def _other_body(self, offset, frame) -> str:
        return "other-body" if offset is not None and np.linalg.norm(offset) > bounding_radius(self.r.frames[frame].shapes) else ""
