"""The order the sync checks run in: the quickest to reject a wrong sync first.

A wrong sync is usually caught by several checks; with ``-x`` (``kill-rate``, a user's first try)
the run stops at the first, so the order decides how long a wrong sync takes to reject. pytest
would run the checks file by file, alphabetically, which puts the cheap vertex checks last. Here
the checks that run a sync are put in the order of :data:`FIRST` (cheapest per scene first, as
measured with ``--durations``), each over the scenes in their registered order; every other test
keeps its place. Verdicts do not depend on the order: every check builds its own scenes.
"""

from __future__ import annotations

__all__ = ["FIRST", "fail_fast"]

#: Check functions, cheapest per scene first; checks not listed follow in collection order.
FIRST = (
    "test_pass_through_is_drawn_overlapping",
    "test_golden_render",
    "test_vertices_match_poses_every_frame",
    "test_vertices_match_in_every_orientation",
    "test_vertices_match_through_teleports_and_kicks",
    "test_sync_keeps_the_mesh",
    "test_sync_does_not_touch_physics",
    "test_syncing_every_frame_equals_syncing_once",
    "test_drawn_bounds_agree_with_get_aabb",
    "test_sync_order_follows_any_order_of_calls",
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
