"""The brick wall with every brick drawn by one shared actor.

Reproduces the guide's "Brick Wall Simulation (Single Actor)" and its section "Rendering multiple
objects by a single actor": the physics is exactly ``brick_wall``'s; only the drawing differs, all
bricks being vertex ranges of one box actor (the ball and the base stay whole actors).
"""

from __future__ import annotations

import inspect

from . import brick_wall
from .base import Scene
from .registry import SceneSpec


def populate(scene: Scene, **params) -> None:
    brick_wall.populate(scene, single_actor=True, **params)


# brick_wall.populate's signature is the one place the parameters and their defaults are written;
# SceneSpec reads them from here, so expose it without the flag this scene fixes.
_signature = inspect.signature(brick_wall.populate)
populate.__signature__ = _signature.replace(
    parameters=[p for name, p in _signature.parameters.items() if name != "single_actor"])


SPEC = SceneSpec(
    name="brick_wall_single",
    title="Brick wall, single actor",
    populate=populate,
    camera=brick_wall.SPEC.camera,
    steps=brick_wall.SPEC.steps,
    chaotic_after=brick_wall.SPEC.chaotic_after,
    origin="guide",
    description="The brick wall scene with all bricks drawn by one shared box actor (vertex sync).",
    parameters=brick_wall.parameters,
)
