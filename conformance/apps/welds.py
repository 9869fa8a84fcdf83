"""Welded frames: links of one body that pyBullet keeps at a constant pose to each other.

A URDF's fixed joints (R2-D2's legs on its body, its finger tips on its fingers) keep a link at one pose
in its parent's frame: no event of the kit can move the two apart, so a vertex either frame holds, the
other holds as well, in every run. Attachment (:mod:`conformance.apps.attachment`) would call such a
vertex undecidable and give it to whichever frame came first, and ``drawn`` would then miss the other
frame. So welded frames are one rigid frame, found from the recording itself (any pair of frames of one
body whose relative pose stays constant at every tick, fixed joints and links a motor holds still
alike), and a vertex they hold goes to the member whose collision shape it lies on.
"""

from __future__ import annotations

import numpy as np

__all__ = ["POSITION", "TURN", "groups"]

#: How far (m) and how much (rad) the relative pose of two welded frames may wander over a run. pyBullet
#: keeps a fixed joint to its own rounding, not exactly: R2-D2's legs turned 1.7e-7 rad and moved 1.3e-7 m
#: against its body over 20 ticks (measured). Frames whose relative pose wanders less than the vertex
#: allowance (2.5e-5 m for a 1 m body, :mod:`conformance.judge.tolerances`) cannot be told apart by the vertices
#: they hold anyway; links that move relative to each other do so by millimetres a tick.
POSITION = 1e-5
TURN = 1e-5


def groups(frames, positions: np.ndarray, rotations: np.ndarray) -> np.ndarray:
    """``(F,)`` a group id per frame (``-1`` for a frame welded to none): frames of the same client and
    body whose relative pose is constant over every tick of ``positions`` ``(T, F, 3)`` and ``rotations``
    ``(T, F, 3, 3)``. Frames that are welded to a common one share its group."""
    count = len(frames)
    parent = list(range(count))

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    by_body: dict[tuple[int, int], list[int]] = {}
    for i, frame in enumerate(frames):
        by_body.setdefault((frame.client, frame.body), []).append(i)
    if positions.shape[0] == 0:
        return np.full(count, -1)
    for members in by_body.values():
        if len(members) < 2:
            continue
        m = np.asarray(members)
        rot = rotations[:, m]                       # (T, k, 3, 3)
        pos = positions[:, m]                       # (T, k, 3)
        # each member's pose in each other's frame, at every tick: Rᵢᵀ Rⱼ and Rᵢᵀ (pⱼ − pᵢ)
        relative = np.einsum("tiba,tjbc->tijac", rot, rot)
        offset = np.einsum("tiba,tijb->tija", rot, pos[:, None, :, :] - pos[:, :, None, :])
        turn = np.abs(relative - relative[:1]).max(axis=(0, 3, 4))
        shift = np.linalg.norm(offset - offset[:1], axis=-1).max(axis=0)
        for a, b in zip(*np.nonzero(np.triu((turn <= TURN) & (shift <= POSITION), 1))):
            parent[root(int(m[a]))] = root(int(m[b]))
    roots = np.array([root(i) for i in range(count)])
    sizes = np.bincount(roots, minlength=count)
    return np.where(sizes[roots] > 1, roots, -1)
