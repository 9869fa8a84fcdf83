"""``compare_vertices``' records (:class:`conformance.judge.compare.VertexResults`): kept as arrays and made
into :class:`~conformance.judge.compare.VertexResult` records when read, they must say what a list of every
target's record says: the worst in tolerances (a NaN first) and the failures, in target order."""

from __future__ import annotations

import numpy as np
import pytest

import wrong_syncs
from conformance import sync
from conformance.judge import compare
from conformance.sync import runner


def _by_ratio(r):
    return (r.error != r.error, r.error / r.tolerance if r.tolerance else r.error)


@pytest.mark.parametrize("spec, frames", [("reference", 3), ("wrong_syncs:OneStepLate", 3)])
def test_the_worst_and_the_failures_are_those_of_the_records(spec, frames):
    implementation = sync.load(spec) if spec == "reference" else sync.SyncImplementation(
        spec=spec, target=spec, factory=wrong_syncs.OneStepLate)
    with runner.running("brick_wall_single", implementation) as run:
        run.advance(frames)
        results = compare.compare_vertices(run.drawing, run.frame)
        records = list(results)
    assert len(records) == len(run.drawing.targets) > 1
    assert results.worst() == max(records, key=_by_ratio)
    assert results.failures() == [r for r in records if not r.ok]
    assert bool(results.failures()) == (spec != "reference")
    assert results[-1] == records[-1] and results[1:3] == records[1:3]


def test_a_nan_error_is_the_worst_and_a_failure():
    with runner.running("free_fall", sync.load("reference")) as run:
        results = compare.compare_vertices(run.drawing, run.frame)
    error = np.array(results.error)
    error[-1] = np.nan  # as no finite drawing gives: compare_vertices makes a non-finite error inf
    odd = compare.VertexResults(run.drawing, run.frame, error, results.tolerance, results._vertex,
                                results._expected, results._actual)
    assert np.isnan(odd.worst().error) and [r.target for r in odd.failures()] == [run.drawing.targets[-1].name]
