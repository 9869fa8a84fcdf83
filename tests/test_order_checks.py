"""The sync-order state machine (``conformance/test_sync_order.py``) kills the order-dependent mistakes in
``order_syncs``, which pass every other check (measured: the commit that added them), and passes every right sync.

The machine runs under the ``triage`` profile here (derandomized, not shrunk), so every run of this file
tries the same programs; a wrong sync must fail the check on at least one of its scenes with a message
that names the scene and frame, the error against the tolerance, the calls that led there and how to rerun.
"""

from __future__ import annotations

import re

import pytest
from hypothesis import settings

from conformance import sync
from conformance.discrimination import verdicts
from conformance import test_sync_order as order
from conformance.checks.pytest_helpers import Kit
from conformance.judge.tolerances import DEFAULT

RIGHT = ["reference", *verdicts.implementations("right_syncs")]
WRONG = verdicts.implementations("order_syncs")

#: What a failure must say: the error against the tolerance at ``[scene(params), frame N``, then the calls, then the rerun.
MESSAGE = re.compile(r"error \S+ m > tolerance \S+ m \[(?P<scene>\w+)\(.*\), frame \d+, sync '[^']+'.*"
                     r"\nafter the calls: .*sync.*\nrerun: python -m pytest --pyargs conformance .*"
                     r"-k 'test_sync_order_follows_any_order_of_calls and (?P=scene)' --sync \S+", re.S)


@pytest.fixture
def triage():
    """The ``triage`` profile for one test, as ``--hypothesis-profile triage`` sets it for a run."""
    before = settings.get_current_profile_name()
    settings.load_profile("triage")
    yield
    settings.load_profile(before)


def failures(spec: str) -> dict[str, str]:
    """Each scene of the check on which ``spec`` fails, with the message."""
    found = {}
    for scene in order.SCENES:
        try:
            order.test_sync_order_follows_any_order_of_calls(scene, Kit(sync.load(spec), DEFAULT))
        except pytest.fail.Exception as failed:
            found[scene] = str(failed)
    return found


@pytest.mark.parametrize("spec", [pytest.param(s, id=s.partition(":")[2]) for s in WRONG])
@pytest.mark.full("the same verdict as CI's kill-rate runs (test_discrimination), which run every right and order sync through the sync-order machine")
def test_the_machine_kills_an_order_dependent_mistake(spec, triage):
    found = failures(spec)
    assert found, f"the sync-order check should fail {spec} on some scene of {order.SCENES}, but passed it on all"
    for scene, message in found.items():
        assert MESSAGE.search(message), f"{spec} on {scene}: the message does not say where, what and how to rerun:\n{message}"


@pytest.mark.parametrize("spec", [pytest.param(s, id=s.partition(":")[2] or s) for s in RIGHT])
@pytest.mark.full("the same verdict as CI's kill-rate runs (test_discrimination), which run every right and order sync through the sync-order machine")
def test_the_machine_passes_a_right_sync(spec, triage):
    found = failures(spec)
    assert not found, f"the sync-order check should pass the right sync {spec}, but failed: {found}"

