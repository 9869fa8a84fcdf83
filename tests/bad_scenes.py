"""Deliberately broken scenes: each breaks one promise that a scene check must catch.

They are not registered at import; tests register them with ``monkeypatch`` for one test at a time.
"""

from __future__ import annotations

import pybullet

from conformance.scenes import Camera, SceneSpec, Shape

CAMERA = Camera((3, -3, 2), (0, 0, 0.5), (0, 0, 1))


def _ball(scene, position=(0, 0, 1), drawn_radius=0.2, collision_radius=0.2):
    shape = Shape("sphere", (collision_radius,))
    body = scene.p.createMultiBody(baseMass=1, baseCollisionShapeIndex=shape.collision_shape(scene.p),
                                   basePosition=list(position))
    scene.bind("ball", body, -1, Shape("sphere", (drawn_radius,)))
    return body


def unseeded(scene, *, count: int = 3) -> None:
    import random

    for i in range(count):
        _ball(scene, position=(random.random(), i, 1.0))  # no seed: differs run to run


def hash_ordered(scene, *, count: int = 3) -> None:
    # str hashes are salted per process (PYTHONHASHSEED), so this is stable within a process only.
    names = sorted({"alpha", "beta", "gamma"}, key=hash)[:count]
    for i, name in enumerate(names):
        _ball(scene, position=(0.5 * i + 0.01 * (ord(name[0]) - 96), 0, 1.0))


def leaky(scene, *, count: int = 1) -> None:
    pybullet.connect(pybullet.DIRECT)  # a second client the scene never closes
    _ball(scene)


def bad_link(scene, *, count: int = 1) -> None:
    body = _ball(scene)
    scene.bind("ghost", body, 3, Shape("sphere", (0.2,)))


def too_big(scene, *, count: int = 1) -> None:
    _ball(scene, drawn_radius=0.25, collision_radius=0.2)


def explodes(scene, *, speed: float = 1.0) -> None:
    body = _ball(scene)
    scene.p.resetBaseVelocity(body, [speed * float("inf"), 0, 0])


def _spec(name, populate, parameters=None):
    return SceneSpec(name=name, title=name, populate=populate, camera=CAMERA, steps=20, origin="canonical",
                     parameters=parameters)


def _speeds():
    from hypothesis import strategies as st

    return st.fixed_dictionaries({"speed": st.floats(0.5, 2.0)})


UNSEEDED = _spec("bad_unseeded", unseeded)
HASH_ORDERED = _spec("bad_hash_ordered", hash_ordered)
LEAKY = _spec("bad_leaky", leaky)
BAD_LINK = _spec("bad_link", bad_link)
TOO_BIG = _spec("bad_too_big", too_big)
EXPLODES = _spec("bad_explodes", explodes, parameters=_speeds)
NO_STRATEGY = _spec("bad_no_strategy", too_big)
