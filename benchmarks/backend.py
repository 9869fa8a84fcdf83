"""The bench's renderer-specific code, all of it, one class per backend: how the floor writes to actors
(:mod:`.floor`), which per-body actor writes the reads table times (:mod:`.reads`), and which
libraries the machine line names (:mod:`.machine`).

Everything else in ``benchmarks/`` goes through ``conformance.backends`` (build, vertex check, render)
or through the names at the bottom of this module, bound to the backend in force
(``conformance.backends.NAME``, which follows the installed FURY). Each class imports its renderer
only when used, so the other one's is never needed.

Measured on this kit's machine (1,000 whole actors, per body, a step between frames): FURY 2's
``actor.local.position = p`` costs ~0.4-0.6 µs, ``local.rotation = q`` as much again, and
``local.matrix = M`` ~18-19 µs, some 30-45 times more: pygfx keeps an actor's transform as position,
rotation and scale, so a matrix set whole is decomposed (``la.mat_decompose``) on every call. The
floor therefore writes ``local.position``; the reads table times all three in every run.
"""

from __future__ import annotations

import contextlib
from typing import Callable, Iterator, Sequence

import numpy as np

from conformance import backends

__all__ = ["FLOOR_WRITES", "LIBRARIES", "Pygfx", "Vtk", "actor_writes", "shared_writes", "whole_writes"]

#: name -> (what the row shows, a call writing one value per body); every call writes ``bodies`` values.
Rows = dict[str, tuple[str, Callable[[], object]]]


class Vtk:
    """FURY 0.12: actors are ``vtkActor``; a pose is a user matrix, vertex data a ``vtkPoints`` array."""

    LIBRARIES = ("vtk",)

    FLOOR_WRITES = ("plus one numpy write over the shared actor's vertices (and normals) and `Modified()`, or one "
                    "`SetUserMatrix` of a prepared `vtkMatrix4x4` per whole actor (the same one every frame: after the "
                    "first, VTK returns at once, so this is the price of the one Python-to-VTK call a sync cannot "
                    "avoid per actor).")

    @staticmethod
    def shared_writes(actors: Sequence) -> Callable[[], None]:
        """Per actor, its vertices (and normals) as at set-up written back by numpy, and ``Modified()``."""
        from vtkmodules.util import numpy_support

        shared = []
        for actor in actors:
            data = actor.GetMapper().GetInput()
            arrays = [data.GetPoints().GetData()]
            if data.GetPointData().GetNormals() is not None:
                arrays.append(data.GetPointData().GetNormals())
            shared.append((data, [(array, numpy_support.vtk_to_numpy(array).copy()) for array in arrays]))

        def write() -> None:
            for data, arrays in shared:
                for array, prepared in arrays:
                    numpy_support.vtk_to_numpy(array)[...] = prepared
                data.GetPoints().Modified()
                if len(arrays) > 1:
                    data.GetPointData().GetNormals().Modified()
        return write

    @staticmethod
    def whole_writes(actors: Sequence) -> Callable[[], None]:
        """Per actor, one ``SetUserMatrix`` of a ``vtkMatrix4x4`` made at set-up."""
        from vtkmodules.vtkCommonMath import vtkMatrix4x4

        whole = [(actor, vtkMatrix4x4()) for actor in actors]

        def write() -> None:
            for actor, matrix in whole:
                actor.SetUserMatrix(matrix)
        return write

    @staticmethod
    @contextlib.contextmanager
    def actor_writes(bodies: int) -> Iterator[Rows]:
        """The C call a whole-actor sync adds per body on VTK: refilling its user matrix."""
        from vtkmodules.vtkCommonMath import vtkMatrix4x4

        matrices, elements = [vtkMatrix4x4() for _ in range(bodies)], tuple(float(k) for k in range(16))
        copy = vtkMatrix4x4.DeepCopy
        yield {"`vtkMatrix4x4.DeepCopy(m, 16 numbers)`, in a loop": (
            "what a whole-actor sync adds per body: the user matrix", lambda: [copy(m, elements) for m in matrices])}


class Pygfx:
    """FURY 2: actors are ``pygfx.Mesh``; a pose is ``actor.local`` (position, rotation, scale), vertex
    data ``geometry.positions``/``normals``, announced with ``update_full()``."""

    LIBRARIES = ("pygfx", "wgpu")

    FLOOR_WRITES = ("plus one numpy write over the shared actor's vertices (and normals) and `update_full()`, or one "
                    "`actor.local.position = p` of a prepared position per whole actor (the one Python call per actor "
                    "a FURY 2 sync cannot avoid; the cheapest such call: `local.matrix = M` costs some 30 times more, "
                    "pygfx decomposing the matrix on every call).")

    @staticmethod
    def shared_writes(actors: Sequence) -> Callable[[], None]:
        """Per actor, its positions (and normals) as at set-up written back by numpy, and ``update_full()``."""
        shared = []
        for actor in actors:
            geometry = actor.geometry
            buffers = [b for b in (geometry.positions, getattr(geometry, "normals", None)) if b is not None]
            shared.append([(buffer, buffer.data.copy()) for buffer in buffers])

        def write() -> None:
            for buffers in shared:
                for buffer, prepared in buffers:
                    buffer.data[...] = prepared
                    buffer.update_full()
        return write

    @staticmethod
    def whole_writes(actors: Sequence) -> Callable[[], None]:
        """Per actor, one ``local.position =`` of its position at set-up (a float64 array made then)."""
        whole = [(actor.local, np.array(actor.local.position, dtype=np.float64)) for actor in actors]

        def write() -> None:
            for transform, position in whole:
                transform.position = position
        return write

    @staticmethod
    @contextlib.contextmanager
    def actor_writes(bodies: int) -> Iterator[Rows]:
        """The calls a whole-actor sync makes per body on FURY 2, on the actors of a grid of ``bodies``
        whole actors (built by ``backends.build``, as the sync figures' are), each given its own pose."""
        from . import grid

        with grid.grid(bodies, shared=False) as scene:
            drawing = backends.build(scene)
            transforms = [t.actor.local for t in drawing.targets]
            poses = [scene.p.getBasePositionAndOrientation(t.body) for t in drawing.targets]
            arrays = [np.array(position, dtype=np.float64) for position, _ in poses]  # as the floor prepares them
            matrices = []
            for position, orientation in poses:
                m = np.identity(4)
                m[:3, :3] = np.reshape(scene.p.getMatrixFromQuaternion(orientation), (3, 3))
                m[:3, 3] = position
                matrices.append(m)

            def set_position():
                for transform, p in zip(transforms, arrays):
                    transform.position = p

            def set_position_and_rotation():
                for transform, (p, q) in zip(transforms, poses):
                    transform.position = p
                    transform.rotation = q

            def set_components():
                for transform, (p, q) in zip(transforms, poses):
                    transform.components = (p, q, None)

            def set_matrix():
                for transform, m in zip(transforms, matrices):
                    transform.matrix = m

            yield {
                "`actor.local.position = p`, in a loop": (
                    "the floor's write: the one call per actor a FURY 2 sync cannot avoid", set_position),
                "`actor.local.position = p; actor.local.rotation = q`, in a loop": (
                    "what `reference` writes per whole actor: pybullet's pose as it is", set_position_and_rotation),
                "`actor.local.components = (p, q, None)`, in a loop": (
                    "the same pose in one call: position and rotation, one change flagged", set_components),
                "`actor.local.matrix = M`, in a loop": (
                    "a 4x4 set whole: pygfx decomposes it into position, rotation and scale", set_matrix),
            }


_IN_FORCE = {"vtk": Vtk, "pygfx": Pygfx}[backends.NAME]

#: The libraries the backend draws with, whose versions :func:`.machine.machine` records.
LIBRARIES: tuple[str, ...] = _IN_FORCE.LIBRARIES
#: The floor's writes in words, for :data:`.floor.DEFINITION`.
FLOOR_WRITES: str = _IN_FORCE.FLOOR_WRITES
#: ``shared_writes(actors)``: a call writing each shared actor's prepared vertices and announcing them.
shared_writes = _IN_FORCE.shared_writes
#: ``whole_writes(actors)``: a call making each whole actor's one unavoidable pose write.
whole_writes = _IN_FORCE.whole_writes
#: ``with actor_writes(bodies) as rows``: the per-body actor writes the reads table times.
actor_writes = _IN_FORCE.actor_writes
