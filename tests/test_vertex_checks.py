"""The vertex check rejects wrong syncs and accepts right ones written in other styles."""

from __future__ import annotations

import pytest

from conformance import sync
from conformance import test_vertices as checks
from conformance.pytest_helpers import Kit
from conformance.tolerances import DEFAULT

Failed = pytest.fail.Exception


@pytest.mark.parametrize("spec", ["syncs:DoesNothing", "syncs:OneStepLate", "syncs:TransposedRotation", "guide-actor"])
def test_vertex_check_rejects_a_wrong_sync(spec):
    with pytest.raises(Failed, match=r"is drawn at .* but should be at .*\[free_fall\(.*frame \d+.*\nreproduce: "):
        checks.test_vertices_match_poses_every_frame("free_fall", Kit(sync.load(spec), DEFAULT))


@pytest.mark.parametrize("spec", ["reference", "syncs:UserMatrixSync"])
def test_vertex_check_accepts_a_right_sync(spec):
    checks.test_vertices_match_poses_every_frame("free_fall", Kit(sync.load(spec), DEFAULT))
