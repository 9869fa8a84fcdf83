"""Spheres, boxes and cylinders of random sizes, at uniformly random orientations, tumbling onto a plate.

For checks of syncing many bodies of every shape kind at arbitrary orientations, drawn either each
by its own actor or by one shared actor per kind (the guide's single-actor recipe). Sizes, poses
and velocities come from ``numpy.random.default_rng(seed)`` alone and do not depend on
``grouping``, so both groupings simulate exactly the same thing. pybullet's default damping is kept.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from conformance.errors import InvalidArgument

from .base import Camera, Scene, Shape
from .registry import SceneSpec

KINDS = ("sphere", "box", "cylinder")
COLORS = {"sphere": (0.9, 0.3, 0.2), "box": (0.2, 0.4, 0.9), "cylinder": (0.2, 0.7, 0.3)}
# One radius/height ratio for every cylinder: FURY can draw cylinders in one actor only then.
CYLINDER_HEIGHT = 2.5  # × radius
SHARED_ACTORS = {"sphere": "spheres", "box": "boxes", "cylinder": "cylinders"}  # grouping="by_kind"
PLATE = (4.0, 4.0, 0.05)  # half extents; the plate's top face is z = 0
REGION = ((-1.2, 1.2), (-1.2, 1.2), (0.4, 2.6))  # where centres are drawn from (grown if crowded)


def populate(scene: Scene, *, count: int = 12, seed: int = 0, size_range: tuple = (0.08, 0.25),
             moving: float = 0.5, grouping: str = "per_body") -> None:
    if grouping not in ("per_body", "by_kind"):
        raise InvalidArgument(f"grouping={grouping!r}, but should be 'per_body' or 'by_kind'")
    lo, hi = (float(s) for s in size_range)
    if not 0 < lo <= hi:
        raise InvalidArgument(f"size_range={size_range!r}, but should be (low, high) with 0 < low <= high")
    rng = np.random.default_rng(seed)
    # Balanced kinds in random order, so every kind is present once count >= 3.
    kinds = [KINDS[i] for i in rng.permutation(np.arange(count) % len(KINDS))]
    shapes = []
    for kind in kinds:
        shade = 0.75 + 0.25 * rng.random()
        color = tuple(float(c * shade) for c in COLORS[kind])
        if kind == "sphere":
            size = (float(rng.uniform(lo, hi)),)
        elif kind == "box":
            size = tuple(float(s) for s in rng.uniform(lo, hi, 3))
        else:
            r = float(rng.uniform(lo, hi))
            size = (r, CYLINDER_HEIGHT * r)
        shapes.append(Shape(kind, size, color=color))
    orientations = Rotation.random(count, random_state=rng).as_quat() if count else np.empty((0, 4))
    centres = _scatter(rng, [_bounding_radius(s) for s in shapes])

    scene.add_body("ground", Shape("box", PLATE, color=(0.6, 0.6, 0.6)), mass=0.0, position=(0.0, 0.0, -PLATE[2]))
    for i, (shape, centre, orientation) in enumerate(zip(shapes, centres, orientations)):
        actor = SHARED_ACTORS[shape.kind] if grouping == "by_kind" else None
        body = scene.add_body(f"{shape.kind}{i}", shape, mass=500.0 * _volume(shape),  # a light wood
                              position=tuple(float(c) for c in centre),
                              orientation=tuple(float(q) for q in orientation), actor=actor)
        if rng.random() < moving:  # `moving` is the chance that a body starts thrown and spinning
            linear = rng.uniform(-1.2, 1.2, 3)
            angular = rng.uniform(-8.0, 8.0, 3)
            scene.p.resetBaseVelocity(body, linear.tolist(), angular.tolist())


def _volume(shape: Shape) -> float:
    if shape.kind == "sphere":
        return 4 / 3 * np.pi * shape.size[0] ** 3
    if shape.kind == "box":
        return 8 * shape.size[0] * shape.size[1] * shape.size[2]
    return np.pi * shape.size[0] ** 2 * shape.size[1]


def _bounding_radius(shape: Shape) -> float:
    if shape.kind == "sphere":
        return shape.size[0]
    if shape.kind == "box":
        return float(np.linalg.norm(shape.size))
    return float(np.hypot(shape.size[0], shape.size[1] / 2))


def _scatter(rng: np.random.Generator, radii: list[float]) -> np.ndarray:
    """Centres in REGION whose bounding spheres do not overlap (overlaps would start with a violent
    push-apart); the region grows upward when it gets crowded, so this always ends."""
    centres: list[np.ndarray] = []
    lows = np.array([r[0] for r in REGION])
    highs = np.array([r[1] for r in REGION])
    for radius in radii:
        attempts = 0
        while True:
            candidate = rng.uniform(lows, highs)
            candidate[2] = max(candidate[2], radius + 0.05)  # clear of the plate
            if all(np.linalg.norm(candidate - c) > radius + rc + 0.02 for c, rc in zip(centres, radii)):
                centres.append(candidate)
                break
            attempts += 1
            if attempts % 50 == 0:
                highs[2] += 0.5
    return np.array(centres).reshape(-1, 3)


def parameters():
    from hypothesis import strategies as st

    return st.fixed_dictionaries({
        "count": st.integers(1, 20),
        "seed": st.integers(0, 2**32 - 1),
        "size_range": st.tuples(st.floats(0.04, 0.3), st.floats(0.04, 0.3)).map(lambda t: tuple(sorted(t))),
        "moving": st.sampled_from([0.0, 0.5, 1.0]),
        "grouping": st.sampled_from(["per_body", "by_kind"]),
    })


SPEC = SceneSpec(
    name="mixed_shapes",
    title="Mixed shapes",
    populate=populate,
    camera=Camera((6.93, -8.72, 5.47), (-0.24, -0.11, 1.31), (0.0, 0.0, 1.0), view_angle=30.0, clipping_range=(0.5, 20.0)),
    # 1.5 s: everything has landed (the highest start falls in ~0.7 s) and is tumbling or settling.
    steps=360,
    # Measured with conformance.checks.determinism.first_divergence: a 1 nm nudge of every body exceeds the physics
    # verdict's tolerance after step 153 (bodies tumbling into a pile).
    chaotic_after=153,
    origin="canonical",
    description="Twelve spheres, boxes and cylinders, randomly sized and oriented, some thrown, fall onto a plate.",
    parameters=parameters,
    examples=({"grouping": "by_kind"},),  # shared actors: vertex rewrites and stored normals
    golden_variants=({"grouping": "by_kind"},),  # shared spheres: their normals and ranges must reach the screen
)
