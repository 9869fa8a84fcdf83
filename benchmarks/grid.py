"""The bench's scenes: many bodies that never touch, so that a step costs what the bodies cost.

Built like the kit's reference scenes (a :class:`~conformance.scenes.SceneSpec` whose ``populate``
adds bodies and bindings; ``backends.build`` draws them), so the ``World`` and ``Target`` a sync is
handed are the genuine article, but not registered: the conformance checks never see them.

``grid``: ``bodies`` bricks (the guide's 0.2 × 0.4 × 0.2 m) on a square grid 1 m apart, in zero
gravity, each given a small random velocity and spin so that every pose changes every step, with
sleeping disabled so that pyBullet never stops moving them. In a stack, 10,000 bricks took minutes a
step (every brick in contact); apart, a step costs about what a sync does. ``shared=True`` draws them
all with one FURY actor (vertex ranges), else each with its own whole actor.

``chains``: bodies of ``links`` links each (revolute joints, also spinning in zero gravity), to
measure reading the poses of links rather than bases.
"""

from __future__ import annotations

import math

import numpy as np
import pybullet

from conformance.scenes import Camera, Scene, SceneSpec, Shape

__all__ = ["CHAINS", "GRID", "chains", "grid"]

BRICK = Shape("box", (0.1, 0.2, 0.1), color=(0.8, 0.5, 0.3))
SPACING = 1.0  # m between neighbours: 0.55 m of gap, which the drift below takes minutes of steps to close


def _populate_grid(scene: Scene, *, bodies: int = 1000, shared: bool = False, seed: int = 0) -> None:
    side = max(1, math.ceil(math.sqrt(bodies)))
    rng = np.random.default_rng(seed)
    velocities = rng.normal(0.0, 0.02, (bodies, 3))  # m/s: a few mm per second of simulated time
    spins = rng.normal(0.0, 1.0, (bodies, 3))  # rad/s: the orientation changes visibly every step
    for i in range(bodies):
        row, column = divmod(i, side)
        body = scene.add_body(f"brick_{i}", BRICK, mass=0.5, position=(column * SPACING, row * SPACING, 1.0),
                              actor="bricks" if shared else None)
        scene.p.resetBaseVelocity(body, velocities[i].tolist(), spins[i].tolist())
        scene.p.changeDynamics(body, -1, activationState=pybullet.ACTIVATION_STATE_DISABLE_SLEEPING)


def _populate_chains(scene: Scene, *, bodies: int = 10, links: int = 100, seed: int = 0) -> None:
    rng = np.random.default_rng(seed)
    p = scene.p
    shape = p.createCollisionShape(pybullet.GEOM_BOX, halfExtents=[0.05, 0.05, 0.05])
    for i in range(bodies):
        body = p.createMultiBody(
            baseMass=1.0, baseCollisionShapeIndex=shape, basePosition=[0.0, i * 2.0, 1.0],
            linkMasses=[0.1] * links, linkCollisionShapeIndices=[shape] * links,
            linkVisualShapeIndices=[-1] * links, linkPositions=[[0.12, 0.0, 0.0]] * links,
            linkOrientations=[[0.0, 0.0, 0.0, 1.0]] * links, linkInertialFramePositions=[[0.0, 0.0, 0.0]] * links,
            linkInertialFrameOrientations=[[0.0, 0.0, 0.0, 1.0]] * links, linkParentIndices=list(range(links)),
            linkJointTypes=[pybullet.JOINT_REVOLUTE] * links, linkJointAxis=[[0.0, 0.0, 1.0]] * links)
        p.resetBaseVelocity(body, [0.0, 0.0, 0.0], rng.normal(0.0, 1.0, 3).tolist())
        p.changeDynamics(body, -1, activationState=pybullet.ACTIVATION_STATE_DISABLE_SLEEPING)
        scene.bind(f"chain_{i}", body, -1, Shape("box", (0.05, 0.05, 0.05)))
        for link in range(links):
            scene.bind(f"chain_{i}_link_{link}", body, link, Shape("box", (0.05, 0.05, 0.05)))


_CAMERA = Camera((50.0, -60.0, 80.0), (50.0, 50.0, 0.0), (0.0, 0.0, 1.0), clipping_range=(1.0, 500.0))

GRID = SceneSpec(name="bench_grid", title="Bench grid", populate=_populate_grid, camera=_CAMERA, steps=100,
                 origin="canonical", gravity=(0.0, 0.0, 0.0),
                 description="Bricks on a grid 1 m apart in zero gravity, drifting and spinning, never touching.")
CHAINS = SceneSpec(name="bench_chains", title="Bench chains", populate=_populate_chains, camera=_CAMERA, steps=100,
                   origin="canonical", gravity=(0.0, 0.0, 0.0),
                   description="Spinning bodies of many links each, in zero gravity.")


def grid(bodies: int, shared: bool, seed: int = 0) -> Scene:
    """A live grid scene; the caller closes it."""
    return GRID.build(bodies=bodies, shared=shared, seed=seed)


def chains(bodies: int, links: int, seed: int = 0) -> Scene:
    """A live chains scene; the caller closes it."""
    return CHAINS.build(bodies=bodies, links=links, seed=seed)
