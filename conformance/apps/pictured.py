"""The ``pictured`` check: the app's picture shows each body where pyBullet's own renderer shows it.

Every recorded vertex may be right while the picture is wrong: the actor is hidden or transparent, or
(FURY 2) the GPU still holds vertices whose change was announced for the wrong range. At four ticks
of each run (:func:`conformance.apps.picture.picture_ticks`) the kit drew the app's scene from the
app's camera, each face in a code colour, and pyBullet's segmentation mask from the same camera
(:mod:`conformance.apps.picture`). Here each face is labelled by the frame the attachment (:mod:`conformance.apps.attachment`) gives the first of its corners one frame alone holds (a corner two frames hold equally, on a joint, says nothing), and each
frame's FURY pixels are held to its pyBullet pixels with the silhouette check's own comparison and
thresholds (:func:`conformance.rendering.silhouettes.compare_silhouettes`: IoU with a 1 px edge slack,
at least 0.98 for boxes and spheres and 0.7 for cylinders, frames covering 50 pixels or more, pixels
where two bodies in contact meet left out).

Which frames are judged, and what the others are:

* a frame whose drawing ``placed`` judged (its vertices span its one box, sphere or cylinder) is
  judged, by its kind's threshold; so is a frame of one such shape whose every drawing ``placed``
  refused as another shape (nothing draws what pyBullet simulates: diagnosis ``not-its-shape``);
* static bodies (mass 0) are background in both pictures: an app may draw them (a ground plate) or not
  at all, as the vertex checks allow; a drawing pyBullet does not have (held by the world, or a
  decoration ``placed`` refused) and a vertex no frame holds are left out, since what they hide cannot
  be told;
* every other frame — a decoration ``placed`` did not judge beside a drawing of the shape, a body nothing draws (the ``drawn``
  check's), a capsule or mesh — is unknown: pixels where either picture shows one are left out, since
  what it hides cannot be told;
* faces fainter than :data:`conformance.apps.picture.FAINT` show nothing of their frame;
* a frame that shows only an edge in both pictures (:func:`edges_only`) is left out;
* where a sphere or cylinder hides another body, the pixels its two outlines (tessellated differently
  by the two renderers) disagree on within :data:`ROUNDED_SLACK` pixels are left out
  (:func:`rounded_outlines`), as the silhouette check leaves out the edge of each body;
* a soft body some drawn vertex follows is judged as one body, every pixel of a face whose first vertex
  follows one of its nodes against every pixel pyBullet's renderer draws of it, by a box's threshold
  (:func:`soft_labels`): its vertices may all follow their nodes while its triangles join other nodes
  (diagnosis ``face-order``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from conformance.apps import picture
from conformance.rendering import silhouettes

__all__ = ["UNKNOWN", "check", "labels"]

#: The label of a pixel that is left out of every frame's comparison.
UNKNOWN = -2
#: Pixels by which two renderers' outlines of one sphere or cylinder may differ where it hides another
#: body (:func:`rounded_outlines`). FURY's are 16-gons, whose outline lies up to 1 - cos(π/16) = 1.9 % of
#: the radius inside the circle, and the tiny renderer tessellates them otherwise: 1.9 px for the kit's
#: chain discs (1 m across, about 100 px in radius). Measured: without it a brick of 80 px behind the
#: brick wall's ball failed a perturbed run (IoU 0.975, 2 pixels 1 px off), and the kit's ``chain`` scene
#: wrapped as an app (tests/test_app_wrapped.py) a disc's 52-pixel sliver of rim at 0.676 with 1 px,
#: 0.714 with 2 (the silhouette check's cylinders need 0.7).
ROUNDED_SLACK = 2


def _statuses(judgement) -> tuple[set[int], set[int], set[int]]:
    """The frames judged in pictures, the background ones (static bases), and the judged frames that
    nothing draws as their shape; all others are unknown. pyBullet's renderer draws a frame's visual
    shapes where it has any (a URDF's), else its collision shapes: a frame is judged where a drawing it
    holds is that shape."""
    r = judgement.r
    background = {i for i, f in enumerate(r.frames) if f.mass == 0 and f.link == -1}
    judged, refused, elsewise = set(), set(), set()
    for _track, _a, frame, _rows, result in judgement.placements():
        drawn = "visual" if r.frames[frame].visuals else "collision"
        if result.judged and result.shape == drawn:
            judged.add(frame)
        elif result.judged and result.ok:
            elsewise.add(frame)  # right, as another of its shapes (its collision shape where pyBullet draws a visual)
        else:
            refused.add(frame)
    refused -= elsewise
    kinds = {i for i, f in enumerate(r.frames) if (not f.visuals and len(f.shapes) == 1 and f.shapes[0][0] in silhouettes.MIN_IOU)
             or (f.visuals and all(v[0] in silhouettes.MIN_IOU or v[0] == "mesh" for v in f.visuals))}
    # A body whose every drawing is another shape than the one pyBullet draws (FURY 0.12's own chain demo draws
    # 1 m discs as thin rods) is still held to pyBullet's picture of it: "a picture that is not what the
    # physics says is wrong". A body with a decoration beside a drawing of its shape stays unknown.
    unlike = (refused - judged - background) & kinds
    return ((judged - refused - elsewise - background) & kinds) | unlike, background, unlike


def soft_labels(judgement) -> dict[int, int]:
    """Each node frame of a soft body that some drawn vertex follows → the body's first node frame, which
    stands for the whole body in the pictures (pyBullet's renderer draws a soft body as one surface)."""
    r = judgement.r
    first: dict[tuple, int] = {}
    for i, f in enumerate(r.frames):
        if f.node >= 0:
            first.setdefault((f.client, f.body), i)
    if not first or not judgement.attachments:
        return {}
    held = np.unique(np.concatenate([a.frame[a.held] for a in judgement.attachments]))
    drawn = {first[(r.frames[i].client, r.frames[i].body)] for i in held.tolist() if i >= 0 and r.frames[i].node >= 0}
    return {i: first[(f.client, f.body)] for i, f in enumerate(r.frames)
            if f.node >= 0 and first[(f.client, f.body)] in drawn}


def limits_of(frame) -> tuple[float, tuple[float, float] | None]:
    """The silhouette threshold and sphere rounding of what pyBullet's renderer draws of ``frame``: its visual
    shapes where it has any (a mesh is drawn from the same triangles by both: a box's threshold), else its
    one collision shape; a soft body's node stands for its surface, drawn from the same triangles by both
    when the app is right: a box's threshold."""
    if frame.node >= 0:
        return silhouettes.MIN_IOU["box"], None
    kinds = [v[0] for v in frame.visuals] or ([frame.shapes[0][0]] if len(frame.shapes) == 1 else [])
    if not kinds:
        return 1.0, None
    limit = min(silhouettes.MIN_IOU.get(kind, silhouettes.MIN_IOU["box"]) for kind in kinds)
    return limit, (silhouettes.ROUNDING.get(kinds[0]) if len(kinds) == 1 else None)


def labels(shot: dict, recording, attachments, judged: set[int], background: set[int],
           decorations: np.ndarray | None = None, soft: dict[int, int] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """``(fury, bullet)``: each pixel's judged frame index in the two pictures of ``shot``, -1 for none
    or background, and -1 in both where either shows an unknown frame or a ``decorations`` vertex (a
    mask over every actor's vertices, in order; left out); a soft body's node frames all carry the label
    ``soft`` gives them (:func:`soft_labels`)."""
    # A vertex no frame holds (``attached`` fails it) is unknown: its best guess may be the world, and as
    # background it would count against every body it hides. So is a decoration pyBullet does not have
    # (FURY's own demos add actor.axes() at the origin, in front of two bricks of the brick wall).
    owner = (np.concatenate([np.where(a.held, a.frame, UNKNOWN) for a in attachments]).astype(np.int64)
             if attachments else np.zeros(0, np.int64))
    # A face stands for the frame of its first corner that one frame alone holds: a corner two frames hold
    # equally (the centre of a chain disc's cap, on the spherical joint, never moves in either link) went
    # to either, and labelled the whole cap fan as the neighbour's (measured: FURY 0.12's chain example,
    # a joint reset, a disc's cap "drawn" over two discs in front of it, IoU 0.367).
    tied = (np.concatenate([a.tied for a in attachments]).astype(bool) if attachments else np.zeros(0, bool))
    vertices = picture.pixel_vertices(shot, (owner != UNKNOWN) & ~tied if len(owner) else None)
    if decorations is not None:
        owner[decorations] = UNKNOWN
    frames = len(recording.frames)
    # frame → label: judged frames themselves, background -1, the rest unknown; the world (-1) is background;
    # the entry after the world is for vertices held by nothing
    table = np.full(frames + 2, UNKNOWN, dtype=np.int64)
    table[frames] = -1
    for f in background:
        table[f] = -1
    for f in judged:
        table[f] = f
    for f, label in (soft or {}).items():
        table[f] = label
    seen = vertices >= 0
    fury = np.where(vertices == UNKNOWN, UNKNOWN, -1).astype(np.int64)
    frame_of = np.where(owner == UNKNOWN, frames + 1, np.where(owner < 0, frames, owner))
    fury[seen] = table[frame_of[vertices[seen]]]
    faint = np.asarray(shot["faint"], dtype=bool)
    fury[seen & (fury >= 0) & faint[np.where(seen, vertices, 0)]] = -1  # too faint to show its frame
    bullet = np.asarray(shot["bullet"], dtype=np.int64)
    bullet = np.where(bullet >= 0, table[np.where(bullet >= 0, bullet, frames)], -1)
    out = (fury == UNKNOWN) | (bullet == UNKNOWN)
    if "fury_depth" in shot:
        out |= undecided(shot, fury, bullet, background)
    fury[out], bullet[out] = -1, -1
    return fury.astype(np.int32), bullet.astype(np.int32)


#: Relative depths closer than this are a tie: which of two surfaces each renderer shows is its rounding's choice.
TIE = 1e-3
#: FURY's surface this much (relative) behind pyBullet's static body is hidden by it: above the two depths'
#: rounding (float32; the kit's plane through a face's corners against the tiny renderer's interpolation, 1e-6
#: apart where both show one body), below any contact penetration seen at a grazing angle
HIDDEN = 1e-5


def undecided(shot: dict, fury: np.ndarray, bullet: np.ndarray, background: set[int]) -> np.ndarray:
    """``(h, w)`` bool: the pixels the two pictures cannot be compared at, by their depths
    (:func:`conformance.apps.picture.face_depth`, pyBullet's depth buffer):

    * where pyBullet shows a static body in front of what FURY shows there. Static bodies are background in
      both pictures, and an app may leave its ground undrawn: a domino resting in the ground by its contact
      penetration, a gripper the kit's events turned into the floor, show in FURY's picture where pyBullet's
      ground hides them (measured on the zoo: 82 pixels of a fallen domino's lower edge). A body FURY shows
      *in front* of pyBullet's ground there (drawn where pyBullet has only ground) is still compared;
    * where the two show two different bodies at the same depth (within :data:`TIE`): coincident faces of two
      links (the WSG-50 gripper's motor and hinge meshes), where each renderer's rounding picks one;
    * where FURY shows a face from its back and pyBullet shows no body: pyBullet's renderer culls back faces,
      FURY 2 draws them (a single-sided cloth sheet seen from below)."""
    fury_depth = np.asarray(shot["fury_depth"], dtype=np.float64)
    bullet_depth = np.asarray(shot["bullet_depth"], dtype=np.float64)
    raw = np.asarray(shot["bullet"], dtype=np.int64)
    hidden = np.isin(raw, list(background)) & np.isfinite(bullet_depth) & (fury_depth > bullet_depth * (1 + HIDDEN))
    # a face seen from its back, which FURY 2 draws (pygfx's meshes are two-sided) and pyBullet's renderer culls:
    # where pyBullet shows nothing of a body there, the two renderers' rules differ, not the drawing (a cloth
    # mesh's single-sided sheet seen from below, pybullet_data's cloth_z_up.urdf: 72,214 pixels)
    culled = np.asarray(shot.get("fury_back", np.zeros(raw.shape, bool)), dtype=bool) & ((raw < 0) | np.isin(raw, list(background)))
    both = np.isfinite(fury_depth) & np.isfinite(bullet_depth)
    gap = np.abs(np.where(both, fury_depth, 0.0) - np.where(both, bullet_depth, 0.0))
    tie = (fury >= 0) & (bullet >= 0) & (fury != bullet) & both & (gap <= TIE * np.minimum(fury_depth, bullet_depth))
    return hidden | tie | culled


def _decorations(judgement, unlike: set[int]) -> np.ndarray:
    """Over every actor's vertices in order: those drawn as something pyBullet does not have, whose pixels
    are left out — held by the world, or by a frame whose shape ``placed`` refused them as, unless nothing
    draws that frame's shape (``unlike``: then the drawing is the body's, and is judged). A soft body's
    node has no shape to refuse a drawing as: what follows it is the body's drawing."""
    if not judgement.attachments:
        return np.zeros(0, bool)
    starts = dict(zip(map(id, judgement.attachments), np.cumsum([0] + [a.frame.shape[0] for a in judgement.attachments])))
    mask = np.concatenate([a.held & (a.frame < 0) for a in judgement.attachments])
    for _track, a, frame, rows, result in judgement.placements():
        if not result.judged and frame not in unlike and judgement.r.frames[frame].node < 0:
            mask[starts[id(a)] + rows] = True
    return mask


def rounded_outlines(fury: np.ndarray, bullet: np.ndarray, rounded: set[int], slack: int) -> np.ndarray:
    """Pixels where the two pictures show two different judged bodies, one of them a sphere or cylinder
    (``rounded``) seen in the other picture within ``slack`` pixels: where the two renderers' tessellations
    of a rounded outline differ, the body behind it shows in one picture and not in the other."""
    from scipy import ndimage

    contested = (fury >= 0) & (bullet >= 0) & (fury != bullet)
    out = np.zeros(fury.shape, dtype=bool)
    if not contested.any() or slack <= 0:
        return out
    structure = np.ones((2 * slack + 1, 2 * slack + 1), dtype=bool)
    for k in rounded & set(np.unique(np.concatenate([fury[contested], bullet[contested]])).tolist()):
        near_bullet = ndimage.binary_dilation(bullet == k, structure)
        near_fury = ndimage.binary_dilation(fury == k, structure)
        out |= contested & (((fury == k) & near_bullet) | ((bullet == k) & near_fury))
    return out


def edges_only(fury: np.ndarray, bullet: np.ndarray, slack: int = silhouettes.SLACK,
               least: int = silhouettes.MIN_PIXELS) -> np.ndarray:
    """Pixels of the judged frames that show only an edge in both pictures: fewer than ``least`` pixels more
    than ``slack`` pixels inside their outline in either (the rim of a disc behind another, seen edge-on).
    Which renderer's tessellation covers such a sliver decides it pixel by pixel, so it is left out, as the
    edge slack leaves out every outline. Measured: the kit's ``chain`` wrapped as an app, with the
    reference, at tick 10 showed a disc's rim as 54 FURY and 76 pyBullet pixels, none of them more than
    1 px inside (IoU 0.667 against the cylinders' 0.70); a body drawn elsewhere or hidden shows its whole
    silhouette, inside as well as edge, in one of the pictures."""
    from scipy import ndimage

    # One pass per picture for every label's box (find_objects), then the erosion of each box alone: not a
    # whole-picture comparison per body, which a 1,000-body app would pay 1,000 times over.
    pictures = [(labels, ndimage.find_objects(np.maximum(labels, -1) + 1)) for labels in (fury, bullet)]
    thin = []
    for k in np.unique(np.concatenate([fury[fury >= 0], bullet[bullet >= 0]])):
        cores = []
        for labels, boxes in pictures:
            found = boxes[k] if k < len(boxes) else None
            mask = labels[found] == k if found is not None else np.zeros((0, 0), bool)
            if mask.sum() < least:
                cores.append(0)
                continue
            mask = np.pad(mask, 1)
            cores.append(int(ndimage.binary_erosion(mask, iterations=slack).sum()) if slack > 0 else int(mask.sum()))
        if max(cores) < least:
            thin.append(k)
    return np.isin(fury, thin) | np.isin(bullet, thin)


def _rounds(shot: dict, recording, rounding) -> tuple[list, list]:
    """Where each sphere frame is in the picture at the shot's tick, as physics has it (column, row, radius
    in pixels: :func:`conformance.rendering.silhouettes.projected_discs`, from the recorded poses), and each
    cylinder frame's radius on screen (:func:`~conformance.rendering.silhouettes.projected_radii`)."""
    from conformance.apps.picture import Camera
    from conformance.backends import projection

    rounded = [i for i, kind in enumerate(rounding) if kind is not None]
    discs, radii = [None] * len(recording.frames), [None] * len(recording.frames)
    tick = int(shot["tick"])
    if not rounded or not 0 <= tick < len(recording.positions) or not shot.get("camera"):
        return discs, radii
    camera = Camera(**{k: tuple(v) if isinstance(v, list) else v for k, v in shot["camera"].items()})
    size = tuple(shot["size"])
    centres, sizes, kinds = [], [], []
    for i in rounded:
        frame = recording.frames[i]
        kind, dims, position, orientation = frame.visuals[0][:4] if frame.visuals else frame.shapes[0]
        turn = Rotation.from_quat(recording.orientations[tick, i])
        centres.append(turn.apply(position) + recording.positions[tick, i])
        sizes.append(float(dims[0] if kind == "sphere" else dims[1]))  # pyBullet's dims: (r,) or (length, r)
        kinds.append(kind)
    pixels, depth = projection.project(camera, size, np.array(centres))
    per_metre = size[1] / 2 / np.tan(np.radians(camera.view_angle) / 2)
    for i, (column, row), d, radius, kind in zip(rounded, pixels, depth, sizes, kinds):
        if d <= 0:
            continue
        if kind == "sphere":
            discs[i] = (float(column), float(row), radius * per_metre / float(d))
        else:
            radii[i] = radius * per_metre / float(d)
    return discs, radii


def _diagnosis(frames: list[int], shot: dict, recording, attachments) -> str:
    """``hidden`` when the actors drawing ``frames`` (one body's) are hidden or mostly too faint; ``stale-gpu``
    when the GPU holds some of their vertices elsewhere than their arrays; else none."""
    hidden = shot.get("hidden", [])
    faint, stale = np.asarray(shot["faint"], bool), np.asarray(shot["stale"], bool)
    start, held, invisible = 0, [], False
    for k, (track, a) in enumerate(zip(recording.actors, attachments)):
        rows = np.flatnonzero(np.isin(a.frame, frames)) + start
        start += track.vertices.shape[1]
        if len(rows):
            held.append(rows)
            invisible |= bool(k < len(hidden) and hidden[k])
    rows = np.concatenate(held) if held else np.zeros(0, int)
    if invisible or (len(rows) and faint[rows].mean() > 0.5):
        return "hidden"
    if len(rows) and stale[rows].any():
        return "stale-gpu"
    return ""


def _triangles_to_blame(judgement, frame: int) -> bool:
    """Whether a soft body (one of its node frames) failing its picture can only be its triangles: the checks of
    its vertices found none drawn wrong."""
    info = judgement.r.frames[frame]
    return (info.client, info.body) not in judgement.soft_misdrawn


def check(judgement):
    """The ``pictured`` verdict of a :class:`~conformance.apps.judge._Judgement`, with each picture's
    comparison record and, for a failure, its three pictures (``Verdict.pictures``)."""
    from conformance.apps.verdict import DIAGNOSES, Verdict

    r = judgement.r
    verdict = Verdict("pictured", True)
    if not judgement.placed_done:
        judgement.placed()  # which frames the vertex checks found drawn wrong (followed_badly, soft_misdrawn)
    judged, background, unlike = _statuses(judgement)
    soft = soft_labels(judgement)
    members: dict[int, list[int]] = {}
    for f, label in soft.items():
        members.setdefault(label, []).append(f)
    names = [f.label for f in r.frames]
    for label in members:
        f = r.frames[label]
        names[label] = f"{f'client {f.client} ' if f.client else ''}soft body {f.body}" + (f" ({f.name})" if f.name else "")
    limits, rounding = zip(*[limits_of(f) for f in r.frames]) if r.frames else ((), ())
    limits, rounding = list(limits), list(rounding)
    app = Path(r.script).name
    rounded = {i for i in judged if {v[0] for v in r.frames[i].visuals} & {"sphere", "cylinder"}
               or (not r.frames[i].visuals and r.frames[i].shapes and r.frames[i].shapes[0][0] in ("sphere", "cylinder"))}
    worst = None
    decorations = _decorations(judgement, unlike)
    drawn_wrong = judgement.drawn_wrong() | judgement.still
    for shot in r.pictures:
        if "skipped" in shot:
            verdict.notes.append(f"no picture at tick {shot['tick']}: {shot['skipped']}")
            continue
        fury, bullet = labels(shot, r, judgement.attachments, judged, background, decorations, soft)
        outline = rounded_outlines(fury, bullet, rounded, ROUNDED_SLACK)
        fury[outline], bullet[outline] = -1, -1
        rims = edges_only(fury, bullet)
        if rims.any():
            shown = np.concatenate([fury[rims], bullet[rims]])
            slivers = len(np.unique(shown[shown >= 0]))
            verdict.notes.append(f"tick {shot['tick']}: {slivers} {'bodies' if slivers > 1 else 'body'} showed only an edge in "
                                 "both pictures (a sliver, which each renderer's tessellation decides): left out")
            fury[rims], bullet[rims] = -1, -1
        touching = {tuple(p) for p in shot.get("touching", [])}
        discs, radii = _rounds(shot, r, rounding)
        record = silhouettes.compare_silhouettes(fury, bullet, min_iou=limits, rounding=rounding, names=names,
                                                 discs=discs, radii=radii, scene=f"app-{Path(r.script).stem}",
                                                 frame=int(shot["tick"]), touching=touching)
        record.sync = "app"
        record.params = {"events": r.events}
        verdict.notes.extend(shot.get("notes", []))
        bad = int(np.count_nonzero(picture.pixel_vertices(shot) == UNKNOWN))
        if bad:
            verdict.notes.append(f"tick {shot['tick']}: {bad} pixels of FURY's picture were no face's code colour "
                                 "(a shader or texture the kit could not switch off): left out")
        targets = record.details["targets"]
        for t in targets:
            ratio = t["off"] / max(t["allowed_off"], 1)
            worst = ratio if worst is None else max(worst, ratio)
        failing = [t for t in targets if not t["passed"]]

        def why_off(t, shot=shot):
            own = members.get(t["index"], [t["index"]])
            # A soft body whose vertices all follow their nodes (attached, drawn and placed found none
            # wrong) yet whose picture is not pyBullet's: its triangles join other nodes.
            # A frame `attached` found drawn at a wrong pose, `drawn` not drawn, or `placed` off its shape or at another
            # size, is not pictured as its shape for that reason: its picture is not evidence of another shape drawn.
            # Nor is one that never moves: what it holds, every still frame holds alike (a fixed base drawn turned
            # over, its vertices shared out between it and the ground).
            return (_diagnosis(own, shot, r, judgement.attachments)
                    or ("not-its-shape" if t["index"] in unlike and t["index"] not in drawn_wrong else "")
                    or ("face-order" if t["index"] in members and _triangles_to_blame(judgement, t["index"]) else ""))
        verdict.pictures.append((record, silhouettes.mask_images(fury, bullet) if failing else {}))
        explained: dict[str, int] = {}
        first = len(verdict.lines)
        if failing and not verdict.passed:
            # One picture's bodies in full (the first that fails), the later ones a line each: a wall of
            # bricks hidden for the whole run is one mistake, not one per picture.
            worst_t = max(failing, key=lambda t: t["off"] / max(t["allowed_off"], 1))
            diagnoses = sorted({why_off(t) for t in failing} - {""})
            why = f" [{', '.join(diagnoses)}]" if diagnoses else ""
            bodies = f"{len(failing)} bodies" if len(failing) > 1 else "1 body"
            verdict.lines.append(f"{app}, tick {shot['tick']}: as well, {bodies} not where pyBullet's renderer draws "
                                 f"{'them' if len(failing) > 1 else 'it'}, the worst {worst_t['target']} (IoU "
                                 f"{worst_t['iou']:.3f}, at least {worst_t['min_iou']:.2f}){why}")
            verdict.diagnoses.extend(d for d in diagnoses if d not in verdict.diagnoses)
            continue
        for t in sorted(failing, key=lambda t: -t["off"] / max(t["allowed_off"], 1)):
            verdict.passed = False
            diagnosis = why_off(t)
            verdict.lines.append(
                f"{app}, tick {shot['tick']}: {t['target']} is not where pyBullet's renderer draws it from the app's camera: "
                f"{t['off']} pixels off beyond the {record.details['slack']} px edge slack, "
                f"{t['allowed_off']} allowed (IoU {t['iou']:.3f}, at least {t['min_iou']:.2f}; "
                f"{t['fury_pixels']} FURY pixels, {t['pybullet_pixels']} pyBullet pixels; {shot['size'][0]}x{shot['size'][1]} "
                f"picture){f' [{diagnosis}]' if diagnosis else ''}")
            if diagnosis:
                explained[diagnosis] = explained.get(diagnosis, 0) + 1
                verdict.diagnoses.append(diagnosis)
        # One explanation per mistake and picture, under the worst body (a wall of bricks hidden at once
        # is one mistake, and its explanation should not be a hundred lines down)
        verdict.lines[first + 1:first + 1] = [f"    diagnosis [{d}] ({n} of the {len(failing)} failing bodies at this "
                                              f"tick): {DIAGNOSES[d]}" for d, n in explained.items()]
        if not targets:
            verdict.notes.append(f"tick {shot['tick']}: no judged body covers {silhouettes.MIN_PIXELS} pixels in either picture")
    verdict.worst = worst
    if not r.pictures:
        verdict.notes.append("no picture was taken (a recording made without pictures)")
    return verdict


def keep(verdict, results_dir, reproduce: str = "", nodeid: str = "", keep_passing: bool = False) -> list[str]:
    """Write each failing picture's three images (``fury_mask``, ``pybullet_mask``, ``mask_difference``)
    and every record under ``results_dir``, as the scene checks' silhouettes are
    (:func:`conformance.reports.artefacts.write_artefacts`); the paths written, relative to it."""
    from conformance.reports import artefacts

    written = []
    for record, images in verdict.pictures:
        record.reproduce, record.nodeid = reproduce, nodeid
        artefacts.write_artefacts(record, results_dir, images if (not record.passed or keep_passing) else {})
        written.extend(record.images.values())
    return written
