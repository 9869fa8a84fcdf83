"""The small box app (``tests/apps/box_<backend>.py``) as source text, and variants of it that are right
in a way the original is not written: the kit must judge them as it judges the original."""

from __future__ import annotations

import re
from pathlib import Path

from conformance import backends

__all__ = ["BOX", "SOURCE", "on_a_client_of_its_own", "played_back"]

BOX = Path(__file__).parent / "apps" / f"box_{backends.NAME}.py"
SOURCE = BOX.read_text(encoding="utf-8")


def on_a_client_of_its_own(source: str = SOURCE) -> str:
    """The app with an empty client 0 kept for probes and its world on client 1 through pybullet_utils'
    ``BulletClient`` (the pybullet Quickstart's way to run several clients), which binds its client id
    to every call it hands out."""
    variant = source.replace("import pybullet as p\n", "import pybullet\nfrom pybullet_utils import bullet_client\n")
    variant = variant.replace("p.connect(p.DIRECT)\n", "pybullet.connect(pybullet.DIRECT)  # client 0: probes only\n"
                                                      "p = bullet_client.BulletClient(pybullet.DIRECT)\n")
    assert variant.count("bullet_client") == 2 and "p = bullet_client" in variant, "the box app changed: update this"
    return variant


def played_back(drawn: str, source: str = SOURCE) -> str:
    """The app as a kinematic playback: no gravity, and each tick the box is set to its trajectory's pose with
    ``resetBasePositionAndOrientation``, so that a step leaves it exactly where the last tick put it (a
    playback's tie, :mod:`conformance.apps.told_apart`). ``drawn``: ``"at the end"`` (right: step, own move,
    sync), ``"before its own move"`` (step, sync, own move) or ``"before the step"`` (sync, step, own move)."""
    variant = source.replace("p.setGravity(0, 0, -10)\n", "p.setGravity(0, 0, 0)\n")
    body = re.search(r"p\.resetBaseVelocity\((\w+), \[0\.5, 0, 0\], \[1, 2, 3\]\)\n", variant)
    variant = variant.replace(body.group(0), "")  # at rest: a step moves nothing
    variant = variant.replace("def timer_callback(", f"def play(cnt):\n    p.resetBasePositionAndOrientation({body.group(1)}, "
                              "[0.3 * np.sin(cnt / 5), 0, 2], p.getQuaternionFromEuler([cnt / 7, 0.2, 0.1]))\n\n\n"
                              "def timer_callback(")
    step, render = "    p.stepSimulation()\n", "    showm.render()\n"
    assert variant.count(step) == 1 and variant.count(render) == 1 and "def play" in variant \
        and "resetBaseVelocity" not in variant, "the box app changed: update this"
    if drawn == "at the end":
        return variant.replace(step, step + "    play(cnt)\n")
    if drawn == "before its own move":
        return variant.replace(render, "    play(cnt)\n" + render)
    assert drawn == "before the step", drawn
    return variant.replace(step, "").replace(render, step + "    play(cnt)\n" + render)
