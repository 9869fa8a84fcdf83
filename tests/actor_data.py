"""The two things the kit's own tests do to an actor's data behind a sync's back, on either backend:
a writable view of its vertices, and telling the renderer they changed (FURY 0.12: ``vertices_from_actor``
and ``update_actor``; FURY 2: ``geometry.positions.data`` and ``update_full``)."""

from __future__ import annotations

import numpy as np

from conformance import backends

__all__ = ["announce", "vertices"]


def vertices(actor) -> np.ndarray:
    if backends.NAME == "vtk":
        from fury import utils

        return utils.vertices_from_actor(actor)
    return actor.geometry.positions.data


def announce(actor) -> None:
    if backends.NAME == "vtk":
        from fury import utils

        utils.update_actor(actor)
    else:
        actor.geometry.positions.update_full()
