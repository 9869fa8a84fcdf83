"""A row of dominoes on a plate; the first is pushed near its top and the row topples.

Reproduces the guide's "Domino Simulation" (FURY ``docs/examples/viz_domino.py``): ``count``
dominoes 0.1 × 1 × 2 m standing 0.99 m apart along x, the first pushed once with ``force`` at its
centre + (0, 0, ``push_height``), gravity -10.

FURY draws the dominoes with one shared box actor (vertex sync); that is the default here
(``single_actor=True``). With ``single_actor=False`` each domino is a whole actor, which puts the
toppled dominoes' 90° pitch, the gimbal lock the guide warns about, in front of actor syncs.
The base plate is a whole actor either way.
"""

from __future__ import annotations

import numpy as np

from conformance.errors import InvalidArgument

from .base import Camera, ExternalForce, Scene, Shape
from .brick_wall import add_base_plate
from .registry import SceneSpec


def populate(scene: Scene, *, count: int = 10, domino_size: tuple = (0.1, 1.0, 2.0), mass: float = 0.5,
             spacing: float = 0.99, first_x: float = -5.5, y: float = 0.4, friction: float = 0.2,
             restitution: float = 0.1, force: tuple = (100.0, 0.0, 0.0), push_height: float = 1.7,
             base_size: tuple = (20.0, 20.0, 0.2), base_friction: float = 1.0, base_restitution: float = 0.5,
             single_actor: bool = True, seed: int = 0) -> None:
    if count < 1:
        raise InvalidArgument(f"count={count!r}, but there should be at least one domino")
    # FURY sizes the plate 2 × count; 20 m is that for its 10 dominoes, kept fixed so that fewer
    # dominoes still stand on it (the row starts at x = -5.5 whatever the count).
    add_base_plate(scene, base_size, friction=base_friction, restitution=base_restitution)
    sx, sy, sz = domino_size
    colors = np.random.default_rng(seed).random((count, 3))
    dominoes = [
        scene.add_body(f"domino_{i}", Shape("box", (sx / 2, sy / 2, sz / 2), color=tuple(map(float, colors[i]))),
                       mass=mass, position=(first_x + i * spacing, y, sz / 2),
                       actor="dominoes" if single_actor else None, friction=friction, restitution=restitution)
        for i in range(count)
    ]
    scene.actions.append(ExternalForce(dominoes[0], tuple(force), offset=(0.0, 0.0, push_height)))


def parameters():
    from hypothesis import strategies as st

    # Spacing at most half the height, as in the example (0.99 for 2 m): a falling domino's foot
    # slides back on the plate, so a wider gap can leave it lying short of the next one.
    return st.fixed_dictionaries({
        "count": st.integers(1, 5),
        "domino_size": st.tuples(st.floats(0.05, 0.2), st.floats(0.5, 1.5), st.floats(1.2, 2.0)),
        "mass": st.floats(0.2, 2.0),
        "spacing": st.floats(0.3, 0.6),
        "single_actor": st.booleans(),
        "seed": st.integers(0, 2**32 - 1),
    })


SPEC = SceneSpec(
    name="domino",
    title="Domino",
    populate=populate,
    camera=Camera((10.46, -8.13, 6.18), (0.0, 0.0, 0.79), (-0.27, 0.26, 0.9), view_angle=30.0, clipping_range=(0.5, 31.0)),
    steps=301,
    origin="guide",
    description="Ten 2 m dominoes 0.99 m apart; the first is pushed once near its top and the row topples.",
    parameters=parameters,
)
