"""A pybullet module bound to one physics client.

The guide writes ``p.getBasePositionAndOrientation(ball)`` against pybullet's implicit default
client. The kit runs several scenes (and so several clients) in one process, so every scene hands
out a :class:`BoundClient`: it forwards attribute access to :mod:`pybullet` and fills in
``physicsClientId``, which lets the guide's code run unchanged with ``p = world.p``.
"""

from __future__ import annotations

import functools

import pybullet

__all__ = ["BoundClient"]


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
