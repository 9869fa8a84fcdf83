"""The order the sync checks run in: the quickest to reject a wrong sync first.

A wrong sync is usually caught by several checks; with ``-x`` (``kill-rate``, a user's first try)
the run stops at the first, so the order decides how long a wrong sync takes to reject. pytest
would run the checks file by file, alphabetically, which puts the cheap vertex checks last. Here
the checks that run a sync are put in the order of :data:`FIRST`, each over the scenes in their
registered order: the pass-through scene, then the sync-order machine, then the golden render, which
between them reject most mistakes soonest; the checks that build short runs of their own; then the
every-frame check, which pays for each scene's shared run (:mod:`conformance.checks.shared_run`), and the
checks after it, most of which read that run. Every other test keeps its place. Verdicts do not depend on
the order: every check builds its own scenes.
"""

from __future__ import annotations

__all__ = ["FIRST", "fail_fast"]

#: Check functions in the order they run; checks not listed follow in collection order.
FIRST = (
    "test_pass_through_is_drawn_overlapping",
    # The sync-order machine before the golden render: over every scene it costs a third of what the golden
    # render does on FURY 2 (3.1 s against 9.9 s in a right sync's `triage` run), and it is the first to reject
    # 12 of the kit's 24 wrong syncs. Measured with `-x`, `triage`, `/usr/bin/time` (2026-11-28, FURY 2 / FURY
    # 0.12): 6 had reached it behind the golden render (15 / 9 s of CPU each, now 2.3-3.5 / 1.6-2.3 s), 6 the
    # golden render had rejected later in its scenes (6.5-15 / 4.3-8.9 s, now 1.9-4.4 / 1.2-3.1 s); the 2 that
    # only the golden render rejects first pay for the machine's scenes (3 / 2.5 s more). All 24, one after
    # the other: 203 -> 86 s of CPU on FURY 2, 146 -> 75 s on FURY 0.12.
    "test_sync_order_follows_any_order_of_calls",
    # These two cost a scene less than the golden render does (0.15 and 0.09 s against 0.54 s; default profile,
    # FURY 0.12, 2026-11-26), where the every-frame check pays for the scene's shared run (1.7 s a scene): a
    # mistake only they kill (an orientation) is then rejected in about 15 s, where it took 70 s behind the
    # shared runs. Before the golden render, so that a mistake both reject is named (issue 48: a picture that
    # differs names no mistake; the vertices that make it do).
    "test_vertices_match_in_every_orientation",
    "test_vertices_match_through_teleports_and_kicks",
    "test_golden_render",
    "test_vertices_match_poses_every_frame",
    "test_sync_keeps_the_mesh",
    "test_sync_does_not_touch_physics",
    "test_syncing_every_frame_equals_syncing_once",
    "test_drawn_bounds_agree_with_get_aabb",
    "test_silhouettes_match_pybullet_at_golden_frames",
    "test_silhouettes_match_in_any_orientation",
    "test_same_scene_renders_identically",
    "test_no_drift_over_ten_thousand_frames",
)


def fail_fast(items: list, runs_sync) -> None:
    """Reorder ``items`` in place: those for which ``runs_sync(item)`` is true, in the order of
    :data:`FIRST`, into the positions they occupied; the rest stay where they are."""
    slots = [i for i, item in enumerate(items) if runs_sync(item)]
    rank = {name: k for k, name in enumerate(FIRST)}
    ordered = sorted((items[i] for i in slots),
                     key=lambda item: rank.get(getattr(item, "originalname", item.name), len(FIRST)))
    for slot, item in zip(slots, ordered):
        items[slot] = item
