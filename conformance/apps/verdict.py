"""A verdict of app mode (one check on one recording) and the catalogue of mistakes it can name.

Kept apart from :mod:`conformance.apps.judge`, which makes the verdicts, so that the checks it hands off
(:mod:`conformance.apps.pictured`) build theirs without importing it back."""

from __future__ import annotations

from dataclasses import dataclass, field

from conformance.apps import attachment as attach_mod

__all__ = ["DIAGNOSES", "LEAD_ORDER", "Verdict", "lead", "lead_line"]

#: diagnosis id → what it means, for the docs and every failure line
DIAGNOSES = {name: text for name, (text, _) in attach_mod.VARIANTS.items() if name not in attach_mod.ALIASES} | {
    "com-frame": "drawn at the centre-of-mass frame (getBasePositionAndOrientation, or getLinkState()[0:2]) instead "
                 "of the link frame: undo getDynamicsInfo(body, link)[3:5], or read getLinkState()[4:6]",
    "never-moved": "left where it was built while its body moves: the sync never sets this actor (or this range)",
    "other-body": "follows another body's frame: the vertex range or the actor was paired with the wrong body",
    "turned-shape": "the actor was built turned in its body's frame (a box's directions, a cylinder's axis)",
    "offset-sign": "drawn with the centre-of-mass offset applied the wrong way (twice its offset from the link frame, or "
                   "undone twice): the link frame is the centre of mass moved by minus getDynamicsInfo(body, link)[3:5], "
                   "turned by the centre of mass's orientation",
    "visual-frame": "drawn without its visual frame, or with it composed the wrong way round (visual @ link where "
                    "link @ visual is meant, or its offset turned by its own rotation: R_v (x + p_v) where R_v x + p_v "
                    "is meant): a URDF places each visual shape in its link frame "
                    "(getVisualShapeData(body)[i][5:7], the <visual><origin>), which the actor must be moved by, "
                    "after the link's pose",
    "mesh-scale": "drawn without its mesh scale: getVisualShapeData(body)[i][3] (the URDF's <mesh scale>) scales the "
                  "mesh file's vertices",
    "scaled": "drawn at another size than its shape, every part of it by one factor (the line states it), and "
              "nowhere at its size: a scale applied twice or left out, or a size given in other terms (a diameter "
              "where a radius is taken). loadURDF's globalScaling is already in "
              "getVisualShapeData's dimensions, mesh scales and frames, and in every pose: scale nothing again; a "
              "mesh file's vertices take getVisualShapeData(body)[i][3]",
    "before-own-move": "drawn at the pose pyBullet held after the tick's step but before the app's own moves of that "
                       "tick (resetJointState, resetBasePositionAndOrientation: a playback, a teleport): the sync runs "
                       "between them; draw after the app's own moves, at the end of the tick",
    "late-or-own-move": "drawn at the pose of the tick before, which pyBullet still held after this tick's step (a "
                        "step leaves a joint just reset where it was): the sync runs before p.stepSimulation(), or "
                        "after it but before the app's own moves of the tick (resetJointState, "
                        "resetBasePositionAndOrientation), and no run could tell which: draw at the end of the tick, "
                        "after the step and the app's own moves",
    "stale-normals": "the vertices turn but the stored normals do not: turn normals with the same rotation",
    "surface-normals": "the soft body's surface deforms but its stored normals were made for another shape (computed "
                       "once, when the actor was built): recompute them from the drawn vertices and faces after each "
                       "copy of the nodes (utils.normals_from_v_f, then utils.normals_to_actor on FURY 0.12; on FURY 2 "
                       "write geometry.normals.data and call its update_range()), or store none",
    "unannounced": "vertex data changed without telling the renderer, which keeps drawing the old data: call "
                   "utils.update_actor (FURY 0.12); on FURY 2 call update_range (or update_full) on every buffer "
                   "changed, positions and normals, covering each changed range",
    "written-back": "the pose that was drawn (as read, or rounded to float32) is written back into pyBullet "
                    "(\"so physics and graphics agree\"): resetBasePositionAndOrientation also sets the body's "
                    "velocity to zero (pybullet 3.2.7), so the simulation is changed; a sync only reads",
    "hidden": "its actor is hidden (SetVisibility(0) on FURY 0.12, visible = False on FURY 2) or drawn fainter than "
              "opacity 32/255, so the picture does not show a body pyBullet has there: keep each body's actor shown",
    "not-its-shape": "nothing draws the shape pyBullet has for this body: every drawing it holds is another shape "
                     "(another size, or turned) than its visual shapes (getVisualShapeData) or, without them, its "
                     "collision shape, and the picture differs from pyBullet's own: build the actor from those "
                     "shapes' dimensions, frames and scales",
    "skipped": "drawn where it was before the tick's step at some ticks only: at other ticks where pyBullet moved it "
               "it is drawn right, so the sync is not late but skips the body on some condition (zero velocity, "
               "a sleeping flag, a pose it takes as unchanged, every other call): draw every body whenever the "
               "sync is called (README, \"The sync protocol\")",
    "node-order": "drawn at another node than the one it follows: the actor's vertices were built in another order "
                  "than the nodes are copied into them (a mesh file read by another library reorders or merges "
                  "vertices): build the actor from getMeshData(body, -1, flags=p.MESH_DATA_SIMULATION_MESH) and copy "
                  "the nodes in that same order",
    "part-copied": "only some of the soft body's moving nodes are copied into the actor after each step; the "
                   "vertices of the others stay where they were built (a copy that stops short: a slice, a count "
                   "taken from another mesh): copy every node of getMeshData(body, -1, "
                   "flags=p.MESH_DATA_SIMULATION_MESH) into the actor after each step",
    "float16": "drawn at the soft body's nodes rounded to float16 (half precision: 11 bits, a millimetre at two "
               "metres): store the nodes as float32 or float64",
    "soft-posed": "drawn at the soft body's nodes moved again by a pose given to its actor (SetPosition or "
                  "SetUserMatrix on FURY 0.12, local.position or local.rotation on FURY 2: the rigid bodies' "
                  "getBasePositionAndOrientation recipe applied to a soft body too): getMeshData's nodes are "
                  "already in the world's frame, so leave a soft body's actor at the identity pose",
    "face-order": "every vertex follows a node of this soft body, but its triangles are not pyBullet's: the faces were "
                  "built for another order of the vertices than the one the nodes are copied in (np.unique sorts what it "
                  "returns; mesh libraries merge or reorder vertices): build the faces for the node order of "
                  "getMeshData(body, -1, flags=p.MESH_DATA_SIMULATION_MESH) and copy the nodes in that same order",
    "drawn-as-rigid": "every vertex that follows this soft body moves as one rigid piece, turned and moved as a whole, "
                      "while pyBullet's nodes squash and bend: the body is posed as a rigid one (by "
                      "getBasePositionAndOrientation, as a deformable URDF from loadURDF looks like a robot, or by a "
                      "matrix on its actor): copy its nodes, getMeshData(body, -1, flags=p.MESH_DATA_SIMULATION_MESH), "
                      "into the vertices after each step",
    "stale-gpu": "the GPU still holds older vertices of this body: the vertices were written but the range announced "
                 "with positions.update_range(offset, count) does not cover them (offset and count are in vertices); "
                 "announce every range written, or update_full()",
}


#: The diagnoses from the most explanatory to the least, which decides the one a failing run leads with
#: (:func:`lead`). A mistake of the pose or of the tick's order reproduces every drawn vertex of a frame, so it
#: comes first; then what a check sees directly (a write back, a change never announced, a body hidden); then a
#: shape's size and frame; then the generic ones, which say where a drawing is and not why: a link scaled 1.6
#: times is also "not its shape" in the picture and "follows another body" where its vertices left their link.
#: Measured on the zoo's injected mistakes (``python -m conformance confusion``, docs/confusion.md).
LEAD_ORDER = ("before-own-move", "late-or-own-move", "skipped", "previous-step", "wxyz", "scalar-first", "euler-order", "radians-as-degrees",
              "float32-angle-axis", "conjugate", "translation-only", "written-back", "unannounced", "stale-gpu",
              "node-order", "soft-posed", "float16", "part-copied", "face-order", "drawn-as-rigid", "stale-normals", "surface-normals", "hidden", "scaled", "mesh-scale", "com-frame", "visual-frame",
              "offset-sign", "turned-shape", "never-moved", "other-body", "not-its-shape")


def lead(diagnoses) -> str:
    """The diagnosis a failing run leads with, of those its checks named (``diagnoses``, any order): the
    first of :data:`LEAD_ORDER`; "" when none was named. A function of the set alone, so a verdict kept
    as a set of names (the zoo's journal) is led the same way."""
    named = set(diagnoses)
    return next((name for name in LEAD_ORDER if name in named), "")


def lead_line(verdicts) -> str:
    """The line a failing run's report opens with when a check named a mistake: which one and where, or ""."""
    named = {d: check for check, v in reversed(list(verdicts.items())) if not v.passed for d in v.diagnoses}
    first = lead(named)
    return f"the mistake, most likely ({named[first]} names it): {DIAGNOSES[first]}" if first else ""


@dataclass
class Verdict:
    check: str
    passed: bool
    lines: list = field(default_factory=list)
    diagnoses: list = field(default_factory=list)
    worst: float | None = None      # worst error / allowance, where the check measures one
    notes: list = field(default_factory=list)
    #: (ImageCheck, pictures by role) of each picture compared (``pictured``): the artefacts to keep
    pictures: list = field(default_factory=list)
    #: (actor index, start, stop, frame) of each piece named ``late-or-own-move`` (``attached``): where
    #: :mod:`~conformance.apps.told_apart` looks in its telling run
    ties: list = field(default_factory=list)

    def message(self) -> str:
        return "\n".join(self.lines)

    def diagnosed(self, diagnosis: str) -> None:
        """Name the mistake (a key of :data:`DIAGNOSES`) under the last line, if there is one."""
        if diagnosis:
            self.lines.append(f"    diagnosis: {DIAGNOSES[diagnosis]}")
            self.diagnoses.append(diagnosis)
