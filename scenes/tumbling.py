"""Bodies tumbling in free space for a long time: the scene for long-run drift.

No gravity and no damping, so nothing settles: each body spins about an axis close to its
intermediate principal axis, which is unstable (the Dzhanibekov effect), so its orientation keeps
sweeping through every attitude, gimbal lock included. A sync that accumulates per-frame increments
accumulates their rounding too; over ten thousand frames that shows. Some bodies share one actor
(the guide's vertex recipe), one sphere and one box are whole actors, and one box tumbles far from
the origin, where float32 vertex storage is coarsest.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from .base import Camera, Scene, Shape
from .registry import SceneSpec


def populate(scene: Scene, *, count: int = 3, spin: float = 6.0, far: float = 50.0, seed: int = 0) -> None:
    rng = np.random.default_rng(seed)
    orientations = Rotation.random(count + 2, random_state=rng).as_quat()
    bodies = []
    for i in range(count):
        half = (0.3, 0.2, 0.1)  # three distinct moments of inertia
        bodies.append(scene.add_body(f"brick_{i}", Shape("box", half, color=tuple(rng.uniform(0.2, 0.9, 3))),
                                     mass=1.0, position=(i - (count - 1) / 2, 0.0, 1.0),
                                     orientation=orientations[i], actor="bricks"))
    bodies.append(scene.add_body("ball", Shape("sphere", (0.25,), color=(0.9, 0.3, 0.2)), mass=1.0,
                                 position=(0.0, 1.2, 1.8), orientation=orientations[count]))
    bodies.append(scene.add_body("far_box", Shape("box", (0.4, 0.25, 0.15), color=(0.2, 0.5, 0.9)), mass=2.0,
                                 position=(far, far, far), orientation=orientations[count + 1]))
    for body in bodies:
        scene.p.changeDynamics(body, -1, linearDamping=0, angularDamping=0)
        rotation = Rotation.from_quat(scene.p.getBasePositionAndOrientation(body)[1])
        # Mostly about the local y (intermediate) axis, a little off it so the tumble starts.
        axis = rotation.apply([0.02, 1.0, 0.03])
        scene.p.resetBaseVelocity(body, list(rng.uniform(-0.05, 0.05, 3)), list(spin * axis / np.linalg.norm(axis)))


def parameters():
    from hypothesis import strategies as st

    return st.fixed_dictionaries({
        "count": st.integers(1, 4),
        "spin": st.floats(0.5, 20.0),
        "far": st.floats(0.0, 200.0),
        "seed": st.integers(0, 2**32 - 1),
    })


SPEC = SceneSpec(
    name="tumbling",
    title="Tumbling bodies",
    populate=populate,
    camera=Camera((-0.9, -34.2, 8.4), (-0.9, 0.86, 0.81), (0.0, 0.0, 1.0), view_angle=30.0, clipping_range=(0.5, 40.0)),
    steps=10_000,
    origin="canonical",
    description="Bodies spin near their unstable intermediate axis in zero gravity for 10,000 steps.",
    parameters=parameters,
    gravity=(0.0, 0.0, 0.0),
    poster_step=240,
)
