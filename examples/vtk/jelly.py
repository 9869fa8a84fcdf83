"""Jelly blocks, FURY 0.12: two volumetric soft bodies (tetrahedral meshes) dropped onto a table.

pyBullet simulates each block as a NeoHookean solid of 75 nodes and 192 tetrahedra, in a world reset with
``RESET_USE_DEFORMABLE_WORLD``. The program writes the block's mesh itself (a grid of cubes, each cut into
six tetrahedra) to a legacy VTK file and loads it twice: with ``loadSoftBody``, and through a
``<deformable>`` URDF with ``loadURDF``. A tetrahedral body's inside is never seen, so each is drawn by its
boundary, two ways a user does:

- the first from pyBullet's own visual mesh, ``getMeshData(block, -1)`` without
  ``MESH_DATA_SIMULATION_MESH``: one vertex per corner of each boundary triangle, every corner at a node,
  read again after every step;
- the second from its simulated nodes, ``getMeshData(block, -1, flags=p.MESH_DATA_SIMULATION_MESH)``: every
  node a vertex (the 9 inside ones too, in no triangle), the triangles found once by matching the visual
  mesh's corners to the nodes, and all nodes copied after every step.

Both recompute the normals of the deformed surface and announce the change (``utils.update_actor``).

EXPECT: pass
"""
import itertools
import os
import tempfile

import numpy as np
import pybullet as p
from fury import actor, utils, window


def tetrahedral_block(cells=(4, 4, 2), size=(0.3, 0.3, 0.15)):
    """Nodes and positively oriented tetrahedra of a box: each cube of a grid cut into six along its diagonal."""
    axes = [np.linspace(-s / 2, s / 2, n + 1) for s, n in zip(size, cells)]
    index = {}
    for k, j, i in itertools.product(*(range(n + 1) for n in reversed(cells))):
        index[i, j, k] = len(index)
    points = np.array([(axes[0][i], axes[1][j], axes[2][k]) for (i, j, k) in index])
    tets = []
    for i, j, k in itertools.product(*(range(n) for n in cells)):
        for order in itertools.permutations(range(3)):
            corner, path = [i, j, k], [(i, j, k)]
            for axis in order:
                corner[axis] += 1
                path.append(tuple(corner))
            tets.append([index[c] for c in path])
    tets = np.array(tets)
    a, b, c, d = (points[tets[:, n]] for n in range(4))
    flip = np.einsum("ij,ij->i", np.cross(b - a, c - a), d - a) < 0
    tets[flip, 2], tets[flip, 3] = tets[flip, 3], tets[flip, 2].copy()
    return points, tets


points, tets = tetrahedral_block()
folder = tempfile.mkdtemp()
mesh_file = os.path.join(folder, "block.vtk")
with open(mesh_file, "w") as f:
    f.write(f"# vtk DataFile Version 2.0\nblock\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS {len(points)} float\n")
    f.writelines("%f %f %f\n" % tuple(q) for q in points)
    f.write(f"CELLS {len(tets)} {5 * len(tets)}\n")
    f.writelines("4 %d %d %d %d\n" % tuple(t) for t in tets)
    f.write(f"CELL_TYPES {len(tets)}\n" + "10\n" * len(tets))
urdf_file = os.path.join(folder, "block.urdf")
with open(urdf_file, "w") as f:
    f.write(f"""<?xml version="1.0"?>
<robot name="block"><deformable name="block">
  <inertial><mass value="0.5"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial>
  <collision_margin value="0.006"/><repulsion_stiffness value="800.0"/><friction value="0.5"/>
  <neohookean mu="400" lambda="600" damping="0.001"/>
  <visual filename="{mesh_file}"/>
</deformable></robot>
""")

p.connect(p.DIRECT)
p.resetSimulation(p.RESET_USE_DEFORMABLE_WORLD)
p.setGravity(0, 0, -10)
table = p.createMultiBody(0, p.createCollisionShape(p.GEOM_BOX, halfExtents=[1, 1, 0.05]), basePosition=[0, 0, -0.05])
first = p.loadSoftBody(mesh_file, basePosition=[-0.25, 0, 0.4], baseOrientation=p.getQuaternionFromEuler([0.3, 0.2, 0]),
                       mass=0.5, useNeoHookean=1, NeoHookeanMu=400, NeoHookeanLambda=600, NeoHookeanDamping=0.001,
                       useSelfCollision=0, frictionCoeff=0.5, collisionMargin=0.006)
second = p.loadURDF(urdf_file, basePosition=[0.25, 0, 0.5], baseOrientation=p.getQuaternionFromEuler([-0.3, 0, 0.4]))

# the first block: pyBullet's visual mesh, one vertex per triangle corner
_, corners = p.getMeshData(first, -1)
corners = np.array(corners)
first_faces = np.arange(len(corners)).reshape(-1, 3)
first_actor = actor.surface(corners, faces=first_faces, colors=np.tile([0.9, 0.3, 0.4], (len(corners), 1)))
first_vertices = utils.vertices_from_actor(first_actor)

# the second block: every node a vertex, the boundary's triangles found from the visual mesh's corners
_, nodes = p.getMeshData(second, -1, flags=p.MESH_DATA_SIMULATION_MESH)
nodes = np.array(nodes)
_, seen = p.getMeshData(second, -1)
at = {tuple(n): i for i, n in enumerate(nodes)}
second_faces = np.array([at[tuple(c)] for c in seen]).reshape(-1, 3)
second_actor = actor.surface(nodes, faces=second_faces, colors=np.tile([0.3, 0.7, 0.4], (len(nodes), 1)))
second_vertices = utils.vertices_from_actor(second_actor)

table_actor = actor.box(centers=np.array([[0, 0, -0.05]]), colors=np.array([[0.6, 0.5, 0.4]]),
                        scales=np.array([[2, 2, 0.1]]))
scene = window.Scene()
scene.add(table_actor, first_actor, second_actor)
showm = window.ShowManager(scene=scene, size=(300, 300))
showm.initialize()
scene.set_camera(position=(0, -2, 0.9), focal_point=(0, 0, 0.15), view_up=(0, 0, 1))
counter = itertools.count()


def sync():
    _, now = p.getMeshData(first, -1)
    first_vertices[:] = np.array(now)
    utils.normals_to_actor(first_actor, utils.normals_from_v_f(first_vertices, first_faces))
    utils.update_actor(first_actor)
    _, now = p.getMeshData(second, -1, flags=p.MESH_DATA_SIMULATION_MESH)
    second_vertices[:] = np.array(now)
    utils.normals_to_actor(second_actor, utils.normals_from_v_f(second_vertices, second_faces))
    utils.update_actor(second_actor)


def timer_callback(_obj, _event):
    cnt = next(counter)
    p.stepSimulation()
    sync()
    showm.render()
    if cnt == 200:
        showm.exit()


sync()
showm.add_timer_callback(True, 1, timer_callback)
showm.start()
p.disconnect()
