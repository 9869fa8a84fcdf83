"""Trajectory fingerprints: the same scene parameters must give bit-identical poses.

Gymnasium's ``check_env`` checks that equal seeds give equal observations; here every scene is
rebuilt from scratch (pybullet-facts.md, "Determinism": a fresh world is bit-identical, while
saveState/restoreState is not) and its poses and velocities are hashed after each of N steps.
"""

from __future__ import annotations

import hashlib
import json
import subprocess
import sys
from typing import Any, Mapping

from conformance import scenes
from conformance.bullet import state, truth

__all__ = ["MAX_STEPS", "digest", "digests_in_subprocess", "first_divergence"]

#: Default run length: the scene's own, capped (the tumbling scene runs 10,000 frames).
MAX_STEPS = 400


def digest(name: str, params: Mapping[str, Any] | None = None, steps: int | None = None,
           spec: "scenes.SceneSpec | None" = None) -> str:
    """SHA-1 of the bytes of every binding's pose and velocity (a soft body's nodes) after each of ``steps`` frames
    (default: the scene's step count, at most :data:`MAX_STEPS`)."""
    spec = spec or scenes.get(name)
    h = hashlib.sha1()
    with spec.build(**(params or {})) as scene:
        count = min(scene.steps, MAX_STEPS) if steps is None else steps
        soft = [b.body for b in scene.bindings if b.soft]
        h.update(scene.poses().tobytes())
        for step in range(count):
            scene.advance(step)
            h.update(scene.poses().tobytes())
            h.update(scene.velocities().tobytes())
            for body in soft:  # a soft body's pose says little of its shape: its nodes
                h.update(truth.nodes(scene.p, body).tobytes())
    return h.hexdigest()


def digests_in_subprocess(names: list[str], steps: int | None = None) -> dict[str, str]:
    """The default-parameter digest of each scene, computed by a fresh Python process."""
    # A scene registered at run time (scenes.register in a conftest) is found in the child as a
    # SceneSpec in the module that defines its populate function, on the same sys.path as here.
    modules = sorted({scenes.get(n).populate.__module__ for n in names})
    code = (
        "import importlib, json, sys\n"
        "names, steps, modules, path = json.loads(sys.argv[1])\n"
        "sys.path[:0] = [p for p in path if p not in sys.path]\n"
        "from conformance import scenes\n"
        "from conformance.checks.determinism import digest\n"
        "found = {s.name: s for m in modules for s in vars(importlib.import_module(m)).values()\n"
        "         if isinstance(s, scenes.SceneSpec)}\n"
        "found.update(scenes.SCENES)\n"
        "print(json.dumps({n: digest(n, steps=steps, spec=found[n]) for n in names}))\n"
    )
    out = subprocess.run([sys.executable, "-c", code, json.dumps([names, steps, modules, sys.path])],
                         capture_output=True, text=True)
    if out.returncode != 0:
        raise RuntimeError(f"the fresh process computing scene digests failed:\n{out.stderr[-2000:]}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def first_divergence(scene_name: str, steps: int, distance: float = 1e-9) -> int | None:
    """The first step after which a run nudged by ``distance`` (:func:`conformance.bullet.state.nudged`) differs from the
    plain run beyond the physics verdict's tolerance, or None within ``steps``: where a scene's
    physics turns chaotic, measured."""
    with scenes.build(scene_name) as plain, scenes.build(scene_name) as moved:
        state.nudged(moved, distance)
        for step in range(steps):
            plain.advance(step)
            moved.advance(step)
            if not state.compare(state.capture(moved), state.capture(plain)).ok:
                return step + 1
    return None
