"""Where in its frame a drawing sits: on the body's collision shape, or off it.

Rigid attachment (:mod:`conformance.apps.attachment`) cannot see a drawing held by the right frame at
the wrong place in it: a base drawn at its centre of mass (``getBasePositionAndOrientation``) instead
of its link frame is rigid in the link frame, offset by the inertial position; a vertex range that
follows another body is rigid in that body's frame, far from its shape. What tells them apart is the
shape: when the vertices a frame holds in one actor span the same box, in the frame's axes, as the
frame's one collision shape (``getCollisionShapeData``, a box, sphere or cylinder), the drawn shape *is*
the collision shape, and its centre must then be the shape's centre. "The same box" allows
``bounds_rtol`` (2.5 %) of the shape's size, as the scene checks' bounds check does (FURY's sphere
tessellation reaches 98.1 % of the radius); so does "the centre".

When the extents differ (an app that draws a decoration, or a visual shape other than its collision
shape) the kit says the placement was not judged, and why: it never guesses an offset it cannot know —
unless some of those vertices lie far beyond the shape (more than twice its radius, and 1 cm): those are
drawn with this frame's pose at another body's place, the mistake of a vertex range paired with the wrong
link (FURY's wrecking-ball example), which attachment alone cannot see.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from conformance.judge.tolerances import DEFAULT, Tolerance

__all__ = ["Placement", "bounding_radius", "bounding_sphere", "candidates", "place", "shape_box", "shape_distance"]

#: A drawing of another size than the collision shape is not judged, unless a vertex it holds lies further
#: from the shape's centre than REACH times the shape's radius plus REACH_MARGIN: no decoration of a body
#: reaches that far, while a vertex range paired with the wrong link of a chain does (a link's length away).
REACH = 2.0
REACH_MARGIN = 0.01  # metres


def shape_box(shapes) -> tuple[np.ndarray, np.ndarray] | None:
    """Centre and half extents, in the link frame's axes, of a frame's one box, sphere or cylinder
    collision shape; None for none, several, or other kinds."""
    if len(shapes) != 1:
        return None
    kind, dims, position, orientation = shapes[0]
    if kind == "box":
        half = np.asarray(dims[:3]) / 2
    elif kind == "sphere":
        half = np.full(3, float(dims[0]))
    elif kind == "cylinder":
        half = np.array([dims[1], dims[1], dims[0] / 2])
    else:
        return None
    turned = np.abs(Rotation.from_quat(orientation).as_matrix()) @ half
    if kind == "sphere":
        turned = half
    return np.asarray(position, dtype=np.float64), turned


def bounding_radius(shapes, default: float = 0.05) -> float:
    """How far from its frame's origin a frame's shapes reach (for telling whether it moved)."""
    radii = []
    for shape in shapes:
        box = shape_box([shape])
        if box is not None:
            radii.append(float(np.linalg.norm(box[0]) + np.linalg.norm(box[1])))
    return max(radii, default=default)


def bounding_sphere(shapes, mesh=()) -> tuple[np.ndarray, float]:
    """Centre (in the link frame) and radius of a sphere around a frame's collision shape: its one box,
    sphere or cylinder's; else around its collision ``mesh`` vertices (:attr:`~conformance.apps.bodies.Frame.mesh`);
    else one around the frame's origin."""
    box = shape_box(shapes)
    if box is None and len(mesh):
        points = np.asarray(mesh, dtype=np.float64)
        centre = (points.min(axis=0) + points.max(axis=0)) / 2
        return centre, float(np.linalg.norm(points - centre, axis=1).max())
    if box is None:
        return np.zeros(3), bounding_radius(shapes)
    return box[0], float(np.linalg.norm(box[1]))


def shape_distance(shapes, mesh=(), visuals=()):
    """A function telling how far each of its ``points`` ``(m, 3)`` (link-frame coordinates) lies outside
    a frame's collision shapes, 0 on or inside one: boxes, spheres, cylinders and capsules exactly, mesh
    shapes by the convex hull of ``mesh`` (pyBullet collides a mesh as its hull unless told otherwise); and
    outside each of its ``visuals`` (:attr:`~conformance.apps.bodies.Frame.visuals`, by the hull of their
    points); inf for a frame with none of them (a plane, say). The hulls are computed here, once: the app
    judge asks about one frame for many sets of vertices, and a mesh's hull was most of what that cost."""
    hulls = [_hull(_framed(visual)) for visual in visuals]
    solids = []
    for kind, dims, position, orientation in shapes:
        if kind in ("box", "sphere", "cylinder", "capsule"):
            solids.append((kind, dims, np.asarray(position), Rotation.from_quat(orientation).as_matrix()))
        elif kind == "mesh" and len(mesh) >= 4:
            solids.append((kind, _hull(np.asarray(mesh, dtype=np.float64)), None, None))

    def distance(points: np.ndarray) -> np.ndarray:
        points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        best = np.full(len(points), np.inf)
        for hull in hulls:
            best = np.minimum(best, hull(points))
        for kind, dims, position, matrix in solids:
            if kind == "mesh":
                best = np.minimum(best, dims(points))
                continue
            local = (points - position) @ matrix
            if kind == "box":
                outside = np.maximum(np.abs(local) - np.asarray(dims[:3]) / 2, 0.0)
                found = np.linalg.norm(outside, axis=1)
            elif kind == "sphere":
                found = np.maximum(np.linalg.norm(local, axis=1) - dims[0], 0.0)
            else:
                height, radius = dims[0], dims[1]
                radial = np.linalg.norm(local[:, :2], axis=1)
                if kind == "cylinder":
                    found = np.hypot(np.maximum(radial - radius, 0.0), np.maximum(np.abs(local[:, 2]) - height / 2, 0.0))
                else:  # a segment of half length height/2 along z, swept by the radius
                    along = np.clip(local[:, 2], -height / 2, height / 2)
                    found = np.maximum(np.hypot(radial, local[:, 2] - along) - radius, 0.0)
            best = np.minimum(best, found)
        return best

    return distance


def _hull(vertices: np.ndarray):
    """How far points lie outside the convex hull of ``vertices`` (the largest plane distance, 0 inside),
    as a function of the points; a flat or degenerate hull by its bounding box."""
    from scipy.spatial import ConvexHull, QhullError

    try:
        planes = ConvexHull(vertices).equations
    except (QhullError, ValueError):
        low, high = vertices.min(axis=0), vertices.max(axis=0)
        return lambda points: np.linalg.norm(np.maximum(np.maximum(low - points, points - high), 0.0), axis=1)
    # In float32, about the hull's centre, a block of points at a time: a robot's link mesh has thousands of
    # hull planes (Unitree A1's trunk: 3,158) and tens of thousands of vertices to place, and the whole
    # product in float64 was most of judging it (3.0 s a call); blocks that stay in cache, in float32, take 0.9 s,
    # 6e-8 m from it (the allowances this feeds are 1e-4 m and up).
    centre = vertices.mean(axis=0)
    normals = planes[:, :3].T.astype(np.float32)
    offsets = (planes[:, 3] + centre @ planes[:, :3].T).astype(np.float32)

    def distance(points):
        points = np.asarray(points, dtype=np.float64) - centre
        found = np.empty(len(points))
        for start in range(0, len(points), _BLOCK):
            found[start:start + _BLOCK] = (points[start:start + _BLOCK].astype(np.float32) @ normals + offsets).max(axis=1)
        return np.maximum(found, 0.0)
    return distance


#: points a block in :func:`_hull`'s distance (a block times the planes stays in cache)
_BLOCK = 2048


@dataclass
class Placement:
    """One actor's vertices held by one frame, against that frame's collision shape."""

    judged: bool
    ok: bool
    why: str
    offset: np.ndarray | None = None
    diagnosis: str = ""
    #: which of the frame's shapes the drawing is: "collision", "visual" (one of its visual shapes, or all
    #: of them together), or "" (not judged)
    shape: str = ""
    #: a drawing not judged that is one of the shapes uniformly scaled by this factor (0: none): wrong when
    #: nothing draws its frame at its size (:meth:`~conformance.apps.judge.Judgement.placed` decides)
    scale: float = 0.0


def _box(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    low, high = points.min(axis=0), points.max(axis=0)
    return (low + high) / 2, (high - low) / 2


def _framed(visual) -> np.ndarray:
    """A visual shape's points in the link frame: its own points moved by its local frame."""
    kind, dims, position, orientation, points = visual
    return np.asarray(points, dtype=np.float64) @ Rotation.from_quat(orientation).as_matrix().T + np.asarray(position)


def candidates(shapes, mesh=(), visuals=()) -> list[tuple[str, str, np.ndarray, np.ndarray]]:
    """The shapes a right drawing of a frame may be, each ``(what, which, centre, half extents)`` in the link
    frame's axes: each of its visual shapes, and all of them together (a link drawn from every visual it
    has); its one box, sphere or cylinder collision shape, or its collision mesh."""
    found = []
    # The visual shapes first: where a frame has them pyBullet's renderer draws them, so a drawing that is
    # both (a URDF box whose visual and collision are one) is judged in pictures too.
    framed = [_framed(v) for v in visuals]
    for v, points in zip(visuals, framed):
        found.append((f"its visual shape ({v[0]})", "visual", *_box(points)))
    if len(framed) > 1:
        found.append((f"its {len(framed)} visual shapes together", "visual", *_box(np.concatenate(framed))))
    box = shape_box(shapes)
    if box is not None:
        found.append((f"its collision shape ({shapes[0][0]})", "collision", *box))
    elif len(mesh) and len(shapes) == 1:
        found.append(("its collision mesh", "collision", *_box(np.asarray(mesh, dtype=np.float64))))
    return found


def _mistakes(visuals) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """What a drawing of a frame's visual shapes spans when their usual mistakes are made, ``(diagnosis,
    centre, half)``, for each shape and for all of them together: drawn without its visual frame
    (``getVisualShapeData(...)[5:7]`` left out) or with its turn and offset composed the wrong way round (the
    offset turned too), a mesh drawn without its scale."""
    unframed, swapped, unscaled, factors = [], [], [], set()
    for kind, dims, position, orientation, points in visuals:
        own = np.asarray(points, dtype=np.float64)
        moved, turned = np.linalg.norm(position) > 1e-9, abs(abs(orientation[3]) - 1) > 1e-9
        unframed.append(own if moved or turned else None)
        # The visual frame's own two parts composed the wrong way round, turned after its offset: R_v (x + p_v)
        turn = Rotation.from_quat(orientation).as_matrix()
        swapped.append((own + np.asarray(position)) @ turn.T if moved and turned else None)
        scale = np.asarray(dims[:3], dtype=np.float64)
        scaled = kind == "mesh" and np.all(scale > 0) and np.any(np.abs(scale - 1) > 1e-6)
        unscaled.append(_framed((kind, dims, position, orientation, own / scale)) if scaled else None)
        if scaled:
            factors.add(float(scale[0]) if np.all(np.abs(scale - scale[0]) <= 1e-6 * scale[0]) else 0.0)
    # A mesh scale the same on every axis left out draws the shape at one factor, which is also what leaving
    # out loadURDF's globalScaling draws (pyBullet keeps it in the mesh scale): the drawing cannot tell the two
    # apart, so it is named by what it shows, "scaled", with the factor. One that differs by axis is the mesh's.
    uniform = len(factors) == 1 and 0.0 not in factors
    found = []
    for diagnosis, wrong in (("visual-frame", unframed), ("visual-frame", swapped),
                             ("scaled" if uniform else "mesh-scale", unscaled)):
        if not any(w is not None for w in wrong):
            continue
        factor = next(iter(factors)) if diagnosis == "scaled" else 0.0
        found += [(diagnosis, *_box(w), factor) for w in wrong if w is not None]
        if len(visuals) > 1:  # the link drawn from all its visuals, each with the mistake where it applies
            together = [w if w is not None else _framed(v) for w, v in zip(wrong, visuals)]
            found.append((diagnosis, *_box(np.concatenate(together)), factor))
    return found


def place(reference: np.ndarray, shapes, inertial_position, *, tolerance: Tolerance = DEFAULT, mesh=(),
          visuals=(), inertial_turn=(0.0, 0.0, 0.0, 1.0)) -> Placement:
    """Judge the link-frame coordinates ``reference`` ``(m, 3)`` of the vertices one frame holds in one
    actor against the frame's shapes (:func:`candidates`: its collision shape, its visual shapes as
    ``getVisualShapeData`` holds them, with their local frames and scales); ``inertial_position`` is the
    centre of mass in the link frame (``getDynamicsInfo(body, link)[3]``), to recognise a drawing made at
    the centre of mass, or with its offset the wrong way; ``inertial_turn`` the centre-of-mass frame's turn
    (``[4]``), which turns such a drawing too."""
    shapes_of = candidates(shapes, mesh, visuals)
    if not shapes_of:
        kinds = ", ".join(s[0] for s in shapes) or "none"
        return Placement(False, True, f"not judged: the frame's collision shapes ({kinds}) are not one box, sphere or "
                         "cylinder, and it has no visual shape pyBullet holds")
    drawn_centre, drawn_half = _box(reference)

    def allowance(half) -> float:
        return tolerance.bounds_rtol * 2 * float(np.max(half)) + 1e-9

    # A drawing is right when it is *any* of the shapes of its size in the right place: a frame may have
    # several shapes of one size (the Minitaur's base: two identical boxes at y = ±0.1; R2-D2's merged
    # links), and the drawing of one must not be judged against its twin. So every shape of the drawing's
    # size is tried before any is said to be missed, and a miss is told against the nearest of them.
    sized = []
    for what, which, centre, half in shapes_of:
        room = allowance(half)
        if not np.all(np.abs(drawn_half - half) <= room):
            continue
        offset = drawn_centre - centre
        # A drawing smaller than its shape along an axis may sit anywhere inside it there: the vertices a
        # frame holds may be part of what is drawn for it, the rest held by frames they equally lie on
        # (a wall's inner corners, on the floor and the next wall too, in a pit that never moves).
        slack = room + np.maximum(half - drawn_half, 0.0)
        if np.all(np.abs(offset) <= slack):
            return Placement(True, True, f"on {what}", shape=which)
        sized.append((float(np.linalg.norm(offset)), what, which, centre, room, offset, slack))
    if sized:
        inertial = np.asarray(inertial_position, dtype=np.float64)
        told = []  # (diagnosis, shape) for each shape of the drawing's size, nearest first
        for _, what, which, centre, room, offset, slack in sorted(sized, key=lambda entry: entry[0]):
            diagnosis = ""
            off_com = np.linalg.norm(inertial) > room
            if off_com and np.all(np.abs(offset - inertial) <= room):
                diagnosis = "com-frame"
            for mistake, m_centre, m_half, _ in _mistakes(visuals):
                if not diagnosis and np.all(np.abs(m_half - drawn_half) <= room) and np.all(np.abs(m_centre - drawn_centre) <= room):
                    diagnosis = mistake
            # After the visual shape's mistakes: a URDF whose <inertial> and <visual> share their <origin> (a
            # pendulum's bob) drawn without its visual frame is off by minus the inertial offset too, and a program
            # that draws visual shapes leaves out their frame far oftener than it turns the offset round.
            if not diagnosis and off_com and (np.all(np.abs(offset - 2 * inertial) <= room)
                                              or np.all(np.abs(offset + inertial) <= room)):
                diagnosis = "offset-sign"
            told.append((diagnosis, what, which, centre, offset, slack))
        # the shape a known mistake explains, else the nearest
        diagnosis, what, which, centre, offset, slack = next((t for t in told if t[0]), told[0])
        axis = int(np.argmax(np.abs(offset) - slack))
        return Placement(True, False, f"drawn {np.linalg.norm(offset):.4g} m off {what} (drawn centre "
                         f"{_v(drawn_centre)} in the link frame, the shape's {_v(centre)}; allowed {slack[axis]:.3g} m "
                         f"along {'xyz'[axis]})", offset, diagnosis, which)
    # A drawing made at the centre of mass is the shape moved and turned by the centre-of-mass frame; where that
    # frame is turned (a bicycle's), what it draws may also be what a visual frame left out draws: then neither.
    at_com = _at_turned_com(drawn_centre, drawn_half, shapes_of, inertial_position, inertial_turn, allowance)
    for mistake, m_centre, m_half, factor in _mistakes(visuals):
        room = allowance(m_half)
        if np.all(np.abs(m_half - drawn_half) <= room) and np.all(np.abs(m_centre - drawn_centre) <= room):
            how = (_MISTAKEN[mistake] if not factor else f"at {1 / factor:.4g} times its size: its mesh scale {factor:.4g} "
                   "(getVisualShapeData(...)[3], which holds loadURDF's globalScaling) left out")
            if at_com:
                how += ", or at its centre-of-mass frame (getDynamicsInfo(...)[3:5]), which draws it alike"
            return Placement(True, False, f"drawn as its visual shape {how} (half extents {_v(drawn_half)}, "
                             f"centre {_v(drawn_centre)} in the link frame)", drawn_centre, "" if at_com else mistake, "visual")
    if at_com:
        return Placement(True, False, f"drawn at its centre-of-mass frame, moved and turned by getDynamicsInfo(...)[3:5] "
                         f"(half extents {_v(drawn_half)}, centre {_v(drawn_centre)} in the link frame)", drawn_centre,
                         "com-frame", at_com)
    for what, which, centre, half in shapes_of:
        if np.all(np.abs(np.sort(drawn_half) - np.sort(half)) <= allowance(half)):
            return Placement(True, False, f"drawn turned in its frame: half extents {_v(drawn_half)} in the link frame's "
                             f"axes where {what}'s are {_v(half)}", diagnosis="turned-shape", shape=which)
    # Before the reach: a body drawn 2.56 times its size reaches far, and is not another body's drawing.
    for what, which, centre, half in shapes_of:
        scale = _uniform_scale(drawn_half, half, tolerance.bounds_rtol)
        room = allowance(scale * half) if scale else 0.0
        # Scaled about the link frame (a globalScaling applied twice scales the visual frame's offset too), about
        # the shape's centre, or about a visual mesh's own origin, where its file puts it (a lego brick's at a
        # corner: its scale applied twice to the vertices moves the brick's centre off both).
        if scale and _scaled_about(drawn_centre, centre, scale, room, [v[2] for v in visuals]):
            return Placement(False, True, f"not judged: drawn at {scale:.3g} times the size of {what} (half extents "
                             f"{_v(drawn_half)} where the shape's are {_v(half)})", drawn_centre - centre, "scaled", which, scale)
    what, which, centre, half = shapes_of[0]
    reach = float(np.max(np.linalg.norm(reference - centre, axis=1)))
    limit = REACH * float(np.linalg.norm(half)) + REACH_MARGIN
    if reach > limit:
        return Placement(True, False, f"reaches {reach:.3g} m from {what}'s centre, more than {REACH:g} times "
                         f"the shape's radius ({float(np.linalg.norm(half)):.3g} m) and {REACH_MARGIN:g} m: drawn with this "
                         "frame's pose but elsewhere", drawn_centre - centre, "other-body", which)
    known = "; ".join(f"{what}, half extents {_v(half)}" for what, _, _, half in shapes_of)
    return Placement(False, True, f"not judged: the drawn shape (half extents {_v(drawn_half)}) is none of the frame's "
                     f"shapes ({known})")


def _at_turned_com(drawn_centre, drawn_half, shapes_of, inertial_position, inertial_turn, allowance) -> str:
    """Which of the shapes (``"visual"``, ``"collision"``; "" none) the drawing is, drawn in a turned
    centre-of-mass frame (``p_i + R_i x`` for its points ``x`` in the link frame): the box of that shape's box so
    moved and turned. "" when the centre-of-mass frame is not turned (the sized shapes' test covers it)."""
    turn = Rotation.from_quat(np.asarray(inertial_turn, dtype=np.float64))
    if turn.magnitude() <= 1e-6:
        return ""
    matrix = np.abs(turn.as_matrix())
    for _, which, centre, half in shapes_of:
        com_centre = np.asarray(inertial_position, dtype=np.float64) + turn.apply(centre)
        com_half = matrix @ half  # the box of a box turned
        room = allowance(com_half)
        if np.all(np.abs(com_half - drawn_half) <= room) and np.all(np.abs(com_centre - drawn_centre) <= room):
            return which
    return ""


def _scaled_about(drawn_centre: np.ndarray, centre: np.ndarray, scale: float, room: float, origins=()) -> bool:
    """Whether a drawing whose box is centred at ``drawn_centre`` is a shape (centre ``centre``) scaled by ``scale``
    about the link frame's origin, the shape's centre, or one of ``origins`` (its visual shapes' own origins in
    the link frame, about which a mesh file's vertices are scaled)."""
    if np.all(np.abs(drawn_centre - scale * centre) <= room):
        return True
    return any(np.all(np.abs(drawn_centre - (o + scale * (centre - o))) <= room)
               for o in (centre, *(np.asarray(o, dtype=np.float64) for o in origins)))


def _uniform_scale(drawn_half: np.ndarray, half: np.ndarray, rtol: float) -> float:
    """The factor by which ``half`` scaled is ``drawn_half`` along every axis (within ``rtol`` of the
    largest extent), when it is clearly not 1; else 0. A flat shape (a cloth sheet) is scaled in its plane."""
    largest = float(np.max(half))
    if largest <= 0:
        return 0.0
    axes = half > 0.05 * largest
    scale = float(np.median(drawn_half[axes] / half[axes]))
    if abs(scale - 1) <= 4 * rtol or scale <= 0:
        return 0.0
    return scale if np.all(np.abs(drawn_half - scale * half) <= 2 * rtol * scale * largest + 1e-9) else 0.0


#: How each mistaken drawing of a visual shape is told.
_MISTAKEN = {"visual-frame": "without its visual frame, or with its turn and offset composed the wrong way round "
                             "(getVisualShapeData(...)[5:7])",
             "mesh-scale": "without its mesh scale (getVisualShapeData(...)[3])"}


def _v(values) -> str:
    """Coordinates in metres to 4 digits; under 0.1 µm, the rounding of a centre that is 0 (-5.551e-17 said
    nothing a reader could use), as 0."""
    return "(" + ", ".join(f"{v:.4g}" if abs(v) >= 1e-7 else "0" for v in values) + ")"
