"""The floor: the least a sync must do each frame, written as a sync (it follows the protocol).

Every pose read once with plain pybullet calls
(``pybullet.getBasePositionAndOrientation(b, physicsClientId=c)`` for a base,
``pybullet.getLinkState(b, l, computeForwardKinematics=1, physicsClientId=c)`` for a link), plus the
least that tells VTK something changed:

* per shared actor, one pass over its vertex array: one numpy write of vertices prepared at set-up
  (and of its normals, if it stores any) and ``Modified()``;
* per whole actor, one ``SetUserMatrix`` of a ``vtkMatrix4x4`` prepared at set-up, the same one every
  frame: after the first, VTK returns at once, so this is the price of the one Python-to-VTK call a
  sync cannot avoid making per actor.

Nothing is computed from the poses, so the floor draws nothing right: it is a yardstick, not a
sync. Every sync figure of the bench is a ratio to it, measured in the same run and process.
"""

from __future__ import annotations

import pybullet
from vtkmodules.util import numpy_support
from vtkmodules.vtkCommonMath import vtkMatrix4x4

from conformance.world import World

__all__ = ["DEFINITION", "Floor"]

#: The floor in one sentence, for the tables.
DEFINITION = ("every pose read once with plain pybullet calls (`pybullet.getBasePositionAndOrientation(b, "
              "physicsClientId=c)`), plus one numpy write over the shared actor's vertices and `Modified()`, or one "
              "`SetUserMatrix` of a prepared `vtkMatrix4x4` per whole actor.")


class Floor:
    """Reads every pose once, writes each shared actor once and sets each whole actor's matrix once."""

    def __init__(self, world: World):
        self.client = world.client
        self.bases = [t.body for t in world.targets if t.link == -1]
        self.links = [(t.body, t.link) for t in world.targets if t.link >= 0]
        self.whole = [(t.actor, vtkMatrix4x4()) for t in world.targets if not t.shared]
        self.shared = []
        for actor in {id(t.actor): t.actor for t in world.targets if t.shared}.values():
            data = actor.GetMapper().GetInput()
            arrays = [data.GetPoints().GetData()]
            if data.GetPointData().GetNormals() is not None:
                arrays.append(data.GetPointData().GetNormals())
            self.shared.append((data, [(array, numpy_support.vtk_to_numpy(array).copy()) for array in arrays]))

    def __call__(self) -> None:
        client = self.client
        for body in self.bases:
            pybullet.getBasePositionAndOrientation(body, physicsClientId=client)
        for body, link in self.links:
            pybullet.getLinkState(body, link, computeForwardKinematics=1, physicsClientId=client)
        for data, arrays in self.shared:
            for array, prepared in arrays:
                numpy_support.vtk_to_numpy(array)[...] = prepared
            data.GetPoints().Modified()
            if len(arrays) > 1:
                data.GetPointData().GetNormals().Modified()
        for actor, matrix in self.whole:
            actor.SetUserMatrix(matrix)
