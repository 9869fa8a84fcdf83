"""Write ``jelly.vtk`` and ``jelly.urdf`` beside this script: the tetrahedral block the ``jelly`` scene simulates.

    python scenes/meshes/make_jelly.py

The block is 0.3 x 0.3 x 0.15 m, a grid of 4 x 4 x 2 cubes, each cut into six tetrahedra along its main
diagonal (Kuhn's subdivision, so neighbouring cubes share their faces' diagonals and the mesh is
conforming): 75 nodes (9 of them inside), 192 tetrahedra, 128 boundary triangles. pyBullet reads the
legacy VTK file (``DATASET UNSTRUCTURED_GRID``, cells of type 10) with ``loadSoftBody`` and keeps its
points as the body's nodes, in order. Every tetrahedron is written with a positive volume (corner 3 on the
side of corners 0, 1, 2 that their right-handed normal points to): pyBullet's NeoHookean model took the
same block with half its tetrahedra inside out to 10^5 m within 80 steps.

``jelly.urdf`` loads the same mesh through ``loadURDF`` as a ``<deformable>`` body (the form of
pybullet_data's ``torus_deform.urdf``), with the material the scene gives ``loadSoftBody``.
Only numpy is needed; the output is the same on every run.
"""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
SIZE = (0.3, 0.3, 0.15)
CELLS = (4, 4, 2)

URDF = """<?xml version="1.0"?>
<!-- made by make_jelly.py: the jelly scene's block as a deformable URDF -->
<robot name="jelly">
  <deformable name="jelly">
    <inertial>
      <mass value="0.5" />
      <inertia ixx="0.0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0" />
    </inertial>
    <collision_margin value="0.006"/>
    <repulsion_stiffness value="800.0"/>
    <friction value="0.5"/>
    <neohookean mu="400" lambda="600" damping="0.001" />
    <visual filename="jelly.vtk"/>
  </deformable>
</robot>
"""


def block(cells=CELLS, size=SIZE) -> tuple[np.ndarray, np.ndarray]:
    """The nodes ``(n, 3)`` and positively oriented tetrahedra ``(m, 4)`` of a box centred on the origin."""
    axes = [np.linspace(-s / 2, s / 2, n + 1) for s, n in zip(size, cells)]
    index = {}
    points = []
    for k, j, i in itertools.product(*(range(n + 1) for n in reversed(cells))):
        index[i, j, k] = len(points)
        points.append((axes[0][i], axes[1][j], axes[2][k]))
    tetrahedra = []
    for i, j, k in itertools.product(*(range(n) for n in cells)):
        for order in itertools.permutations(range(3)):  # one path from corner 000 to 111 per tetrahedron
            corner, path = [0, 0, 0], [(0, 0, 0)]
            for axis in order:
                corner[axis] += 1
                path.append(tuple(corner))
            tetrahedra.append([index[i + a, j + b, k + c] for a, b, c in path])
    points, tetrahedra = np.asarray(points), np.asarray(tetrahedra)
    a, b, c, d = (points[tetrahedra[:, n]] for n in range(4))
    inside_out = np.einsum("ij,ij->i", np.cross(b - a, c - a), d - a) < 0
    tetrahedra[inside_out, 2], tetrahedra[inside_out, 3] = tetrahedra[inside_out, 3], tetrahedra[inside_out, 2].copy()
    return points, tetrahedra


def vtk_text(points: np.ndarray, tetrahedra: np.ndarray) -> str:
    lines = ["# vtk DataFile Version 2.0", "jelly: made by make_jelly.py", "ASCII", "DATASET UNSTRUCTURED_GRID",
             f"POINTS {len(points)} float"]
    lines += ["%.6f %.6f %.6f" % tuple(p) for p in points]
    lines.append(f"CELLS {len(tetrahedra)} {5 * len(tetrahedra)}")
    lines += ["4 %d %d %d %d" % tuple(t) for t in tetrahedra]
    lines.append(f"CELL_TYPES {len(tetrahedra)}")
    lines += ["10"] * len(tetrahedra)
    return "\n".join(lines) + "\n"


def main() -> None:
    points, tetrahedra = block()
    (HERE / "jelly.vtk").write_text(vtk_text(points, tetrahedra), encoding="ascii")
    (HERE / "jelly.urdf").write_text(URDF, encoding="ascii")
    print(f"wrote {HERE / 'jelly.vtk'} ({len(points)} nodes, {len(tetrahedra)} tetrahedra) and {HERE / 'jelly.urdf'}")


if __name__ == "__main__":
    main()
