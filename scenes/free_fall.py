"""A single body falling freely, with damping off: the integrator's closed form holds exactly."""

from __future__ import annotations

from .base import Camera, Scene, Shape
from .registry import SceneSpec


def populate(scene: Scene, *, kind: str = "box", size: float = 0.2, mass: float = 1.0,
             height: float = 3.0, orientation: tuple = (0.3, 0.2, 0.1, 0.927), spin: tuple = (1.0, 2.0, 3.0)) -> None:
    sizes = {"box": (size, size * 0.5, size * 1.5), "sphere": (size,), "cylinder": (size, size * 3)}
    body = scene.add_body("body", Shape(kind, sizes[kind], color=(0.9, 0.3, 0.2)),
                          mass=mass, position=(0, 0, height), orientation=_unit(orientation))
    scene.p.changeDynamics(body, -1, linearDamping=0, angularDamping=0)
    scene.p.resetBaseVelocity(body, [0, 0, 0], list(spin))


def _unit(q):
    n = sum(c * c for c in q) ** 0.5
    return tuple(c / n for c in q)


def parameters():
    from hypothesis import strategies as st

    return st.fixed_dictionaries({
        "kind": st.sampled_from(["box", "sphere", "cylinder"]),
        "size": st.floats(0.05, 1.0),
        "mass": st.floats(0.1, 10.0),
    })


SPEC = SceneSpec(
    name="free_fall",
    title="Free fall",
    populate=populate,
    camera=Camera((4.0, -6.0, 2.5), (0.0, 0.0, 2.0), (0.0, 0.0, 1.0), view_angle=30.0, clipping_range=(0.5, 9.0)),
    steps=120,
    origin="canonical",
    description="One spinning body falls from rest under g = -10 with damping switched off.",
    parameters=parameters,
)
