"""The shared run (:mod:`conformance.checks.shared_run`) in a real session: the checks that watch one run of
a scene each keep their own verdict, and a sync that raises fails every one of them with its paragraph.
Each case is pytest on the kit, as a user runs it (``verdicts.check``, records read back)."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from conformance.discrimination import verdicts

TESTS = Path(__file__).resolve().parent
SHARING = ("test_vertices_match_poses_every_frame", "test_sync_keeps_the_mesh", "test_sync_does_not_touch_physics",
           "test_drawn_bounds_agree_with_get_aabb", "test_silhouettes_match_pybullet_at_golden_frames")


def _outcomes(sync_module: str, tmp_path, spec: str, scene: str) -> dict[str, dict]:
    (tmp_path / "sync_under_test.py").write_text(sync_module, encoding="utf-8")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(tmp_path), str(TESTS), os.environ.get("PYTHONPATH", "")]))
    env.pop("CONFORMANCE_SYNC", None)
    outcome = verdicts.check(spec, pytest_args=["-k", f"{scene} and ({' or '.join(SHARING)})"], env=env)
    return {r["check"]: r for r in outcome.records if r["scene"] == scene}


def test_each_check_of_a_shared_run_keeps_its_own_verdict(tmp_path):
    """A sync that writes poses back into pyBullet draws every vertex right: only the physics check
    of the five that watch the shared run fails, and it names the frame."""
    records = _outcomes("from wrong_syncs import WritesPoseBack as Sync\n", tmp_path, "sync_under_test:Sync", "free_fall")
    assert set(records) == set(SHARING)
    failed = {check for check, r in records.items() if r["outcome"] == "failed"}
    assert failed == {"test_sync_does_not_touch_physics"}, {c: r["message"][:200] for c, r in records.items()}
    assert "[free_fall, frame 1" in records["test_sync_does_not_touch_physics"]["message"]


def test_a_sync_that_raises_fails_every_check_that_shares_the_run(tmp_path):
    module = '''
from conformance.implementations.reference import ReferenceSync


class Sync(ReferenceSync):
    frames = 0

    def __call__(self):
        Sync.frames += 1
        if Sync.frames > 5:
            raise RuntimeError("lost the actor")
        super().__call__()
'''
    records = _outcomes(module, tmp_path, "sync_under_test:Sync", "free_fall")
    assert set(records) == set(SHARING)
    for check, record in records.items():
        assert record["outcome"] == "failed", check
        assert "raised on scene 'free_fall' at step 5: RuntimeError: lost the actor" in record["message"], record["message"]


@pytest.mark.full("a whole run of a right sync: CI's kill-rate runs pass every right sync through every check")
def test_a_right_sync_passes_every_check_of_the_shared_run(tmp_path):
    records = _outcomes("from right_syncs import IncrementalSync as Sync\n", tmp_path, "sync_under_test:Sync", "chain")
    assert set(records) == set(SHARING) and all(r["outcome"] == "passed" for r in records.values()), records
