"""What a sync implementation is handed: the scene's client and the things it must move.

This module is backend-neutral: ``Target.actor`` is whatever the backend draws with (for FURY 0.12,
a ``vtkActor``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Mapping

import numpy as np

from conformance.bullet.client import BoundClient

__all__ = ["Target", "World"]


@dataclass(frozen=True, eq=False)
class Target:
    """One body or link to keep in step, and the vertices that draw it.

    ``actor`` draws it with vertices ``start:stop`` of its polydata. When ``shared`` is true other
    targets live in the same actor, so only those vertices may change (the guide's single-actor
    recipe); otherwise the whole actor is this body and its transform may be set instead.

    ``position``/``orientation`` (x, y, z, w) is the world pose of the body's *link frame* at which
    those vertices were drawn when the actor was built: the identity for a whole actor (built at
    the origin, as the guide advises), the initial pose for a shared one (the guide's
    ``brick_centers``/``brick_orns``). The link frame is what ``getLinkState(...)[4:6]`` reports for
    a link and what ``createMultiBody(basePosition=…)`` sets for a base; for the kit's scenes the base
    link frame is also the centre of mass that ``getBasePositionAndOrientation`` reports.

    ``nodes`` is None for a rigid body or link. For a soft body (``loadSoftBody``) it is the simulated
    node each vertex follows: vertex ``start + k`` is drawn at node ``nodes[k]`` of
    ``getMeshData(body, -1, flags=MESH_DATA_SIMULATION_MESH)[1]``, in world coordinates. A soft body
    has no pose to draw it by: its actor keeps the identity transform (``position``/``orientation``
    are the identity) and a sync copies the nodes into the vertices after each step.
    """

    name: str
    body: int
    link: int
    actor: Any
    start: int
    stop: int
    shared: bool
    position: np.ndarray
    orientation: np.ndarray
    nodes: np.ndarray | None = None


@dataclass(frozen=True, eq=False)
class World:
    """Everything a sync implementation may use: ``p`` (pybullet bound to the scene's client),
    the ``targets`` to move and the ``actors`` by name."""

    scene: str
    p: BoundClient
    targets: tuple[Target, ...]
    actors: Mapping[str, Any]

    @property
    def client(self) -> int:
        return self.p.client
