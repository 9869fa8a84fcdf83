"""The mistakes a run cannot always tell apart, by the word a failure names both with.

A sync one step late and one that copied once draw the same at the first frame; a soft body posed as a rigid
one and one posed on its actor as well, too; an app's drawing a step late and one made before its own
``resetJointState`` of the tick, where the step barely moved the arm. A failure names the pair with one word
until a later frame (or run) tells them apart, and the confusion matrix counts the word as none for either
(:mod:`conformance.discrimination.confusion`). No import beyond the standard library: the matrix reads it
without pyBullet.
"""

from __future__ import annotations

__all__ = ["UNDECIDED"]

#: word → the two mistakes it names at once
UNDECIDED = {"late-or-once": ("previous-step", "never-moved"),
             "rigid-or-posed": ("drawn-as-rigid", "soft-posed"),
             "late-or-own-move": ("previous-step", "before-own-move")}
