"""A pybullet module bound to one physics client.

The guide writes ``p.getBasePositionAndOrientation(ball)`` against pybullet's implicit default
client. The kit runs several scenes (and so several clients) in one process, so every scene hands
out a :class:`BoundClient`: it forwards attribute access to :mod:`pybullet` and fills in
``physicsClientId``, which lets the guide's code run unchanged with ``p = world.p``.
"""

from __future__ import annotations

import contextlib
import functools
from typing import Iterator

import pybullet

__all__ = ["NOT_THE_DEFAULT_CLIENT", "BoundClient", "decoy_client"]

#: Said under a sync's pybullet error when the scene is not on pyBullet's default id (:func:`decoy_client`).
NOT_THE_DEFAULT_CLIENT = (
    "The scene is not on pyBullet's client 0: client 0, the default of every pybullet call made without "
    "physicsClientId, is another world here. Read the simulation through world.p (pybullet bound to the "
    "scene's client: p = world.p) or pass physicsClientId=world.client (README, \"The sync protocol\").")


class BoundClient:
    """``pybullet`` with ``physicsClientId`` fixed to ``client`` (like pybullet_utils' BulletClient,
    which cannot wrap an existing connection and disconnects when garbage-collected)."""

    def __init__(self, client: int):
        self._client = int(client)

    @property
    def client(self) -> int:
        return self._client

    def __getattr__(self, name: str):
        attribute = getattr(pybullet, name)
        if callable(attribute) and not isinstance(attribute, type):
            return functools.partial(attribute, physicsClientId=self._client)
        return attribute

    def __repr__(self) -> str:
        return f"BoundClient(client={self._client})"


@contextlib.contextmanager
def decoy_client() -> Iterator[None]:
    """Hold pyBullet's default client id 0 with an empty world while a scene is built and run, so that the
    scene is on another client: a sync that calls pybullet without the scene's client reads nothing there
    and fails, where on client 0 it would draw the right poses by luck (the mutant ``a4f27042dd``,
    docs/discrimination.md). When 0 is taken already, the decoy gets another id and a scene built inside
    is not on 0 either (pyBullet gives a new connection the lowest free id)."""
    decoy = pybullet.connect(pybullet.DIRECT)
    try:
        yield
    finally:
        if decoy >= 0:
            pybullet.disconnect(physicsClientId=decoy)
