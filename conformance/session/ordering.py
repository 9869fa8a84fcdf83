"""The order the sync checks run in: the quickest to reject a wrong sync first.

A wrong sync is usually caught by several checks; with ``-x`` (``kill-rate``, a user's first try)
the run stops at the first, so the order decides how long a wrong sync takes to reject. pytest
would run the checks file by file, alphabetically, which puts the cheap vertex checks last. Here
the checks that run a sync are put in the order of :data:`FIRST`, each over the scenes in their
registered order: the pass-through scene and the golden render, which between them reject most
mistakes soonest; the checks that build short runs of their own, about as cheap a scene (measured
with ``--durations``); then the every-frame check, which pays for each scene's shared run
(:mod:`conformance.checks.shared_run`), and the checks after it, most of which read that run. Every other
test keeps its place. Verdicts do not depend on the order: every check builds its own scenes.
"""

from __future__ import annotations

__all__ = ["FIRST", "fail_fast"]

#: Check functions in the order they run; checks not listed follow in collection order.
FIRST = (
    "test_pass_through_is_drawn_overlapping",
    "test_golden_render",
    # These three cost a scene about what the golden render does or less (0.55, 0.15 and 0.09 s against
    # 0.54 s; default profile, FURY 0.12, 2026-11-26), where the every-frame check pays for the scene's
    # shared run (1.7 s a scene): a mistake only they kill (an order of calls, an orientation) is then
    # rejected in about 15 s, where it took 70 s behind the shared runs.
    "test_sync_order_follows_any_order_of_calls",
    "test_vertices_match_in_every_orientation",
    "test_vertices_match_through_teleports_and_kicks",
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
