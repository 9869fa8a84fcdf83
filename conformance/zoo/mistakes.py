"""The mistakes users make drawing a robot, injected into the zoo's right programs (issue 47, point 2).

Each is one edit of a right program's text (:mod:`conformance.zoo.programs`), the way a user would get it
wrong: the link frame read at the centre of mass, a visual shape's frame left out or composed the wrong
way round, a mesh's scale or ``globalScaling`` left out or applied twice, the quaternion reordered,
the rotation transposed, one link never synced, a sync every other tick or before the step, degrees for
radians, the drawing made before the program's own ``resetJointState`` of the tick. A mistake that changes
nothing a model shows (no inertial offset, no visual frame, a scale of 1, nothing that turns) cannot be
rejected: the zoo tells that apart by comparing the wrong program's drawing with the right one's
(:func:`conformance.zoo.judging.judge_wrong`), never by assuming it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

__all__ = ["LIMITS", "MISTAKES", "Mistake", "inject"]


@dataclass(frozen=True)
class Mistake:
    name: str
    description: str
    #: the diagnosis a user should read for it (issue 48 measures whether they do); "" where none is expected
    diagnosis: str
    edits: Callable[[str, str], list[tuple[str, str]]]   # (drawing, backend) -> [(right text, wrong text)]
    applies: Callable[[object], bool] = lambda style: True


_LINK_FRAME = "    return p.getLinkState(body, link, computeForwardKinematics=1)[4:6]\n"


def _in_link_frame(drawing, backend):
    return [("    return Rotation.from_quat(shape[6]).apply(vertices) + np.asarray(shape[5])\n",
             "    return Rotation.from_quat(shape[6]).apply(vertices + np.asarray(shape[5]))\n")]


def _pose(rewrite: str):
    """An edit of the pose every drawing reads (:func:`link_frame` in the programs): ``rewrite`` is the line
    put before its returns, turning ``pos, orn`` into the mistaken pose."""
    def edits(drawing, backend):
        return [("        return p.multiplyTransforms(com_pos, com_orn, *p.invertTransform(inertial_pos, inertial_orn))\n"
                 + _LINK_FRAME,
                 "        pos, orn = p.multiplyTransforms(com_pos, com_orn, *p.invertTransform(inertial_pos, inertial_orn))\n"
                 "    else:\n        pos, orn = p.getLinkState(body, link, computeForwardKinematics=1)[4:6]\n"
                 f"    {rewrite}\n    return pos, orn\n")]
    return edits


def _visual_frame(drawing, backend):
    if drawing == "shapes":
        return [("shape_actors.append((b, shape[1], frame_matrix(shape[5], shape[6]),",
                 "shape_actors.append((b, shape[1], np.eye(4),")]
    return [("    return Rotation.from_quat(shape[6]).apply(vertices) + np.asarray(shape[5])\n", "    return vertices\n")]


def _visual_order(drawing, backend):
    if drawing == "shapes" and backend == "vtk":
        return [("        matrix = frame_matrix(*link_frame(b, link)) @ visual_frame\n",
                 "        matrix = visual_frame @ frame_matrix(*link_frame(b, link))\n")]
    if drawing == "shapes":
        return [("        shape_actor.local.matrix = frame_matrix(*link_frame(b, link)) @ visual_frame\n",
                 "        shape_actor.local.matrix = visual_frame @ frame_matrix(*link_frame(b, link))\n")]
    return _in_link_frame(drawing, backend)


_SCALE = "        mesh.vertices = np.asarray(mesh.vertices) * np.asarray(dims)\n"
def _unsynced(drawing, backend):
    """One link skipped by the sync: of the bodies that can move, the link (a base only where there is none) drawn
    with the most vertices, so that the mistake shows (a quadruped's toe lies inside its calf's mesh)."""
    size = {"links": "len(pieces[(b, link)][0])", "impostors": "len(pieces[(b, link)][0])",
            "shapes": ("shape_actor.GetMapper().GetInput().GetNumberOfPoints()" if backend == "vtk"
                       else "len(shape_actor.geometry.positions.data)"),
            "shared": "stop - start"}[drawing]
    loop = {"links": "    for (b, link), link_actor in link_actors.items():\n",
            "impostors": "    for (b, link), link_actor in link_actors.items():\n",
            "shapes": "    for b, link, visual_frame, shape_actor in shape_actors:\n",
            "shared": "    for b, link, start, stop, local in parts:\n"}[drawing]
    sized = {"links": "{(b, link): " + size + " for b, link in link_actors}",
             "impostors": "{(b, link): " + size + " for b, link in link_actors}",
             "shapes": "{}",
             "shared": "{}"}[drawing]
    if drawing in ("shapes", "shared"):
        unpack = ("b, link, _, shape_actor" if drawing == "shapes" else "b, link, start, stop, _")
        source = "shape_actors" if drawing == "shapes" else "parts"
        sized = "{}\nfor " + unpack + " in " + source + ":\n    SIZES[(b, link)] = SIZES.get((b, link), 0) + " + size
    skipped = (f"SIZES = {sized}\n"
               "SKIPPED = max(((link >= 0, size, (b, link)) for (b, link), size in SIZES.items() if can_move(b)),\n"
               "              default=(0, 0, None))[2]\n")
    return [("\ndef sync():\n", "\n" + skipped + "\n\ndef sync():\n"),
            (loop, loop + "        if (b, link) == SKIPPED:\n            continue  # forgotten\n")]


def _tick(*pairs):
    def edits(drawing, backend):
        return list(pairs)
    return edits


_DRAW = "    sync()\n    showm.render()\n"
_STEP = "    p.stepSimulation()\n"


MISTAKES = {m.name: m for m in (
    Mistake("com-frame", "each frame drawn at its centre of mass (getBasePositionAndOrientation as it is, "
            "getLinkState()[0:2])", "com-frame",
            lambda drawing, backend: [("        com_pos, com_orn = p.getBasePositionAndOrientation(body)\n",
                                       "        return p.getBasePositionAndOrientation(body)\n"
                                       "        com_pos, com_orn = p.getBasePositionAndOrientation(body)\n"),
                                      (_LINK_FRAME, "    return p.getLinkState(body, link, computeForwardKinematics=1)[0:2]\n")]),
    Mistake("visual-frame", "each visual shape drawn without its frame in the link (getVisualShapeData()[5:7] "
            "left out)", "visual-frame", _visual_frame),
    Mistake("visual-order", "each visual shape's frame composed the wrong way round with its link frame",
            "visual-frame", _visual_order),
    # A mesh scale the same on every axis left out is a drawing at one factor, named "scaled" (placement._mistakes)
    Mistake("mesh-scale", "mesh files drawn without their scale (getVisualShapeData()[3] left out)", "scaled|mesh-scale",
            lambda drawing, backend: [(_SCALE, "")]),
    Mistake("scaling-twice", "globalScaling applied again to shapes pyBullet already scaled", "scaled",
            lambda drawing, backend: [("    return mesh\n\n\ndef in_link_frame", "    mesh.apply_scale(GLOBAL_SCALING)\n"
                                       "    return mesh\n\n\ndef in_link_frame"),
                                      ("\np.loadURDF(\"plane.urdf\")\n", "\nGLOBAL_SCALING = 1.6\np.loadURDF(\"plane.urdf\")\n")],
            applies=lambda style: style.scaling != 1.0),
    Mistake("scaling-left-out", "the shapes drawn at the size of the file, globalScaling left out", "scaled",
            lambda drawing, backend: [("    return mesh\n\n\ndef in_link_frame", "    mesh.apply_scale(1 / GLOBAL_SCALING)\n"
                                       "    return mesh\n\n\ndef in_link_frame"),
                                      ("\np.loadURDF(\"plane.urdf\")\n", "\nGLOBAL_SCALING = 1.6\np.loadURDF(\"plane.urdf\")\n")],
            applies=lambda style: style.scaling != 1.0),
    Mistake("wxyz", "the quaternion reordered to (w, x, y, z) before use", "wxyz", _pose("orn = (orn[3], orn[0], orn[1], orn[2])")),
    Mistake("transposed", "the rotation matrix transposed (the inverse rotation drawn)", "conjugate",
            _pose("orn = Rotation.from_quat(orn).inv().as_quat()")),
    Mistake("degrees", "pyBullet's Euler angles (radians) given to scipy as degrees", "radians-as-degrees",
            _pose("orn = Rotation.from_euler('xyz', p.getEulerFromQuaternion(orn), degrees=True).as_quat()")),
    Mistake("unsynced-link", "one link never synced (the one drawn with the most vertices)", "never-moved", _unsynced),
    Mistake("every-other-tick", "the actors synced every other tick", "skipped",
            _tick((_DRAW, "    if cnt % 2 == 0:\n        sync()\n    showm.render()\n"))),
    Mistake("one-step-late", "the actors synced before p.stepSimulation()", "previous-step",
            _tick((_DRAW, "    showm.render()\n"), (_STEP, "    sync()\n" + _STEP))),
    Mistake("before-reset", "drawn after the step but before the tick's own resetJointState", "before-own-move",
            _tick((_DRAW, "    showm.render()\n"), (_STEP, _STEP + "    sync()\n")),
            applies=lambda style: style.drive == "playback"),
)}


#: The wrong programs app mode accepts though their drawing differs from the right one's, each with the measured
#: reason it cannot see the mistake there: shown in the zoo's table as limits, never counted as rejected.
LIMITS = {
    ("gripper/wsg50_with_r2d2_gripper.sdf", "transposed"):
        "its links only slide (prismatic joints on a static base) and stay turned a half turn about x, to 0.0016 rad: "
        "the transposed rotation is that turn the other way, a constant tilt of 0.0032 rad (0.49 mm at the fingers) "
        "that rigid attachment cannot see and placed's 2.5 % allows, and the kit's events never turn a static base's links",
}


def inject(text: str, mistake: Mistake, drawing: str, backend: str) -> str:
    """``text`` (a right program) with ``mistake`` made; a program the mistake's edits do not find is a fault
    of this module, said at once."""
    found = text
    for right, wrong in mistake.edits(drawing, backend):
        if right not in found:
            raise ValueError(f"mistake {mistake.name!r} finds no {right.strip()[:60]!r} in the {drawing} program "
                             f"for {backend}")
        found = found.replace(right, wrong, 1)
    return found
