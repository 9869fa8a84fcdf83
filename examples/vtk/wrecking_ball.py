"""Wrecking ball, FURY 0.12: a heavy ball on a chain, its hinge pushed once, smashes a block of 125 bricks.

The integration guide's "Wrecking Ball Simulation" for FURY 0.12 (VTK), which joins its two ways of
drawing many bodies. The 125 bricks are vertex ranges of ONE box actor (8 vertices a brick), as in
"Rendering multiple objects by a single actor"; the chain's 14 cylinder links are vertex ranges of ONE
cylinder actor, as in "Rendering Joints". The ball, the chain's last link, is a sphere actor of its own,
and so are the tiny hinge box at the top of the chain and the static plate.

Each range's vertices are captured once in its body's (or link's) own frame and recomputed from
pyBullet's pose after every step: ``world = R(orn) @ local + pos``, with a brick's pose from
``getBasePositionAndOrientation`` and a link's from ``getLinkState(rope, j, computeForwardKinematics=1)[4:6]``
(its link frame as of the last step). The chain actor holds 14 cylinders, so a link's range is its
vertex count divided by 14, not by the brick count. What is drawn is what pyBullet collides: each
cylinder (radius 0.1 m, height 0.1 m) along its link's z axis, half a link below its joint; FURY 0.12
scales its unit cylinder uniformly by ``heights``, hence ``radius=0.1 / 0.1``. ``utils.update_actor``
tells VTK that both shared actors' points changed.

Physics as in the kit's ``wrecking_ball`` scene, which corrects FURY's example: the link positions
are the real (0, 0, -0.1), where FURY's ``astype(int)`` truncated them to 0 and piled every link on
the hinge. A static 5 x 5 x 0.2 m plate (friction 0.3, restitution 0.5); a 5 x 5 x 5 block of
0.2 x 0.4 x 0.2 m bricks of 0.5 kg (friction 0.1, restitution 0.1), brick (i, j, k) centred at
(0.2 i - 1.8, 0.4 j - 0.9, 0.2 k + 0.1); a 0.1 kg hinge box (half extent 0.01 m) pinned at (0, 0, 2)
by a fixed constraint, with 15 spherical-joint links 0.1 m apart below it: 14 cylinders of 0.5 kg
and a 5 kg ball of radius 0.5 m; joint friction as a velocity motor (kp 0, kd 1, force 0.0005).
The hinge is pushed once with 500 N along -x before the first step; gravity -10, 131 steps.

EXPECT: pass
"""

import itertools

import numpy as np
import pybullet as p
from fury import actor, utils, window
from vtkmodules.vtkCommonMath import vtkMatrix4x4

client = p.connect(p.DIRECT)
p.setTimeStep(1 / 240)
p.setGravity(0, 0, -10)
nb_steps = 131
rng = np.random.default_rng(0)

# Base plate (whole actor, static): its top face is z = 0.
base_size = np.array([5.0, 5.0, 0.2])
base_actor = actor.box(centers=np.zeros((1, 3)), directions=np.array([[1.0, 0.0, 0.0]]),
                       scales=np.array([base_size]), colors=np.array([[1.0, 1.0, 1.0]]))
base_coll = p.createCollisionShape(p.GEOM_BOX, halfExtents=list(base_size / 2))
base = p.createMultiBody(baseMass=0, baseCollisionShapeIndex=base_coll,
                         basePosition=[0, 0, -base_size[2] / 2], baseOrientation=[0, 0, 0, 1])
p.changeDynamics(base, -1, lateralFriction=0.3, restitution=0.5)

# Bricks: a 5 x 5 x 5 block, brick (i, j, k) at wall_origin + (0.2 i, 0.4 j, 0.2 k + 0.1).
wall_length, wall_breadth, wall_height = 5, 5, 5
nb_bricks = wall_length * wall_breadth * wall_height
brick_size = np.array([0.2, 0.4, 0.2])
wall_origin = np.array([-1.8, -0.9, 0.0])
brick_centers = np.zeros((nb_bricks, 3))
brick_orns = np.zeros((nb_bricks, 4))
brick_colors = rng.random((nb_bricks, 3))
brick_coll = p.createCollisionShape(p.GEOM_BOX, halfExtents=list(brick_size / 2))
bricks = np.zeros(nb_bricks, dtype=np.int64)  # body ids: int64, an int8 array would overflow
index = 0
for i in range(wall_length):
    for k in range(wall_height):
        for j in range(wall_breadth):
            brick_centers[index] = wall_origin + [i * brick_size[0], j * brick_size[1], (k + 0.5) * brick_size[2]]
            brick_orns[index] = [0, 0, 0, 1]
            bricks[index] = p.createMultiBody(baseMass=0.5, baseCollisionShapeIndex=brick_coll,
                                              basePosition=brick_centers[index].tolist(),
                                              baseOrientation=brick_orns[index].tolist())
            p.changeDynamics(int(bricks[index]), -1, lateralFriction=0.1, restitution=0.1)
            index += 1

# The chain: a hinge box, 14 cylinder links and the ball as its 15th link.
n_links = 15
n_cylinders = n_links - 1
link_length = 0.1
link_radius = 0.1
link_mass = 0.5
link_offset = [0.0, 0.0, -link_length / 2]   # each collision cylinder, in its link frame
ball_radius = 0.5
ball_mass = 5.0
joint_friction = 0.0005
link_colors = rng.random((n_cylinders, 3))

link_coll = p.createCollisionShape(p.GEOM_CYLINDER, radius=link_radius, height=link_length,
                                   collisionFramePosition=link_offset, collisionFrameOrientation=[0, 0, 0, 1])
ball_coll = p.createCollisionShape(p.GEOM_SPHERE, radius=ball_radius)
hinge_half = 0.01
hinge_position = [0.0, 0.0, 2.0]
hinge_coll = p.createCollisionShape(p.GEOM_BOX, halfExtents=[hinge_half] * 3)

rope = p.createMultiBody(baseMass=0.1,
                         baseCollisionShapeIndex=hinge_coll,
                         baseVisualShapeIndex=-1,
                         basePosition=hinge_position,
                         baseOrientation=[0, 0, 0, 1],
                         linkMasses=[link_mass] * n_cylinders + [ball_mass],
                         linkCollisionShapeIndices=[link_coll] * n_cylinders + [ball_coll],
                         linkVisualShapeIndices=[-1] * n_links,
                         linkPositions=[[0.0, 0.0, -link_length]] * n_links,   # floats: not astype(int)
                         linkOrientations=[[0, 0, 0, 1]] * n_links,
                         linkInertialFramePositions=[[0, 0, 0]] * n_links,
                         linkInertialFrameOrientations=[[0, 0, 0, 1]] * n_links,
                         linkParentIndices=list(range(n_links)),   # link j hangs from link j - 1 (0: the hinge)
                         linkJointTypes=[p.JOINT_SPHERICAL] * n_links,
                         linkJointAxis=[[1, 0, 0]] * n_links)

# Joint friction: a velocity motor with no position gain only resists joint motion.
for j in range(n_links):
    p.setJointMotorControlMultiDof(rope, j, p.POSITION_CONTROL, targetPosition=[0, 0, 0, 1],
                                   targetVelocity=[0, 0, 0], positionGain=0, velocityGain=1,
                                   force=[joint_friction] * 3)

# The pin holding the hinge where it was built.
p.createConstraint(rope, -1, -1, -1, p.JOINT_FIXED, [0, 0, 0], [0, 0, 0], hinge_position)

# Actors: one box actor for all bricks, one cylinder actor for the 14 links (built along z at the
# origin), and whole actors for the ball, the hinge and the plate.
brick_actor = actor.box(centers=brick_centers, directions=np.tile([1.0, 0.0, 0.0], (nb_bricks, 1)),
                        scales=np.tile(brick_size, (nb_bricks, 1)), colors=brick_colors)
chain_actor = actor.cylinder(centers=np.zeros((n_cylinders, 3)), directions=np.tile([0.0, 0.0, 1.0], (n_cylinders, 1)),
                             colors=link_colors, radius=link_radius / link_length, heights=link_length,
                             capped=True, resolution=16)
ball_actor = actor.sphere(centers=np.zeros((1, 3)), colors=np.array([[1.0, 0.0, 1.0]]), radii=ball_radius)
hinge_actor = actor.box(centers=np.zeros((1, 3)), directions=np.array([[1.0, 0.0, 0.0]]),
                        scales=np.array([[2 * hinge_half] * 3]), colors=np.array([[1.0, 0.0, 0.0]]))

brick_vertices = utils.vertices_from_actor(brick_actor)   # (1000, 3), a view of VTK's points
brick_sec = brick_vertices.shape[0] // nb_bricks           # 8 vertices a brick (FURY 0.12's box)
chain_vertices = utils.vertices_from_actor(chain_actor)
link_sec = chain_vertices.shape[0] // n_cylinders          # 68 vertices a link: divided by the LINK count

# Each brick's vertices in its own frame, captured once: local = R0^T (v - c0).
brick_local = np.zeros((nb_bricks, brick_sec, 3))
for b in range(nb_bricks):
    rot0 = np.reshape(p.getMatrixFromQuaternion(brick_orns[b].tolist()), (3, 3))
    brick_local[b] = (brick_vertices[b * brick_sec:(b + 1) * brick_sec].astype(np.float64) - brick_centers[b]) @ rot0

# Each link's cylinder in its link frame, captured once: the canonical cylinder moved by the offset.
link_local = [chain_vertices[j * link_sec:(j + 1) * link_sec].astype(np.float64) + link_offset
              for j in range(n_cylinders)]


def pose_matrix(pos, orn):
    """The 4 x 4 user matrix of a link frame: pyBullet's rotation matrix and position."""
    matrix = np.eye(4)
    matrix[:3, :3] = np.reshape(p.getMatrixFromQuaternion(orn), (3, 3))
    matrix[:3, 3] = pos
    user = vtkMatrix4x4()
    user.DeepCopy(matrix.ravel())
    return user


def sync_bricks():
    for b, brick in enumerate(bricks):
        pos, orn = p.getBasePositionAndOrientation(int(brick))
        rot_mat = np.reshape(p.getMatrixFromQuaternion(orn), (3, 3))
        brick_vertices[b * brick_sec:(b + 1) * brick_sec] = brick_local[b] @ rot_mat.T + pos
    utils.update_actor(brick_actor)


def sync_chain():
    # The hinge: the base's inertial frame is its link frame.
    hinge_actor.SetUserMatrix(pose_matrix(*p.getBasePositionAndOrientation(rope)))
    for j in range(n_cylinders):
        pos, orn = p.getLinkState(rope, j, computeForwardKinematics=1)[4:6]
        rot_mat = np.reshape(p.getMatrixFromQuaternion(orn), (3, 3))
        chain_vertices[j * link_sec:(j + 1) * link_sec] = link_local[j] @ rot_mat.T + pos
    utils.update_actor(chain_actor)
    # The ball: the last link, its sphere centred on its link frame.
    ball_actor.SetUserMatrix(pose_matrix(*p.getLinkState(rope, n_links - 1, computeForwardKinematics=1)[4:6]))


base_actor.SetUserMatrix(pose_matrix(*p.getBasePositionAndOrientation(base)))
sync_bricks()
sync_chain()

scene = window.Scene()
scene.add(base_actor, brick_actor, chain_actor, ball_actor, hinge_actor)
scene.set_camera(position=(10.28, -7.1, 6.39), focal_point=(0.0, 0.0, 0.4), view_up=(-0.35, 0.26, 1.0))
showm = window.ShowManager(scene, size=(900, 768), reset_camera=False, order_transparent=True)
showm.initialize()

counter = itertools.count()
apply_force = True


def timer_callback(_obj, _event):
    global apply_force
    cnt = next(counter)

    # Push the hinge once, at its centre, before the first step.
    if apply_force:
        hinge_pos = p.getBasePositionAndOrientation(rope)[0]
        p.applyExternalForce(rope, -1, forceObj=[-500, 0, 0], posObj=hinge_pos, flags=p.WORLD_FRAME)
        apply_force = False

    p.stepSimulation()

    sync_bricks()
    sync_chain()

    showm.render()
    if cnt == nb_steps - 1:
        showm.exit()


showm.add_timer_callback(True, 1, timer_callback)
showm.start()
p.disconnect()
