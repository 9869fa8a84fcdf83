"""The small box app (``tests/apps/box_<backend>.py``) as source text, and variants of it that are right
in a way the original is not written: the kit must judge them as it judges the original."""

from __future__ import annotations

from pathlib import Path

from conformance import backends

__all__ = ["BOX", "SOURCE", "on_a_client_of_its_own"]

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
