"""Golden variants: the default goldens judge the same bodies drawn through shared actors.

``SceneSpec.golden_variants`` lists parameter sets that change how bodies are grouped into actors and
nothing else; ``test_golden_render`` judges each against the default scene's goldens. These tests keep
the two promises that rest on: a variant's reference picture is the default's (so the goldens are
valid for it), and the variant catches what a shared actor gets wrong and the default scene cannot
show (normals left as built, changes never uploaded) — the issue's "no scene with goldens has shared
spheres".
"""

from __future__ import annotations

import pytest

from conformance import backends, scenes, sync
from conformance.sync import runner
from conformance.errors import InvalidArgument
from conformance.checks.pytest_helpers import variant_id
from conformance.rendering import compare, golden, snapshots
from conformance.scenes import SceneSpec

VARIANTS = [(name, dict(v)) for name in scenes.names() for v in scenes.get(name).golden_variants]
# Mistakes that only a shared actor shows: the default mixed_shapes draws every body as a whole actor.
SHARED_ONLY = ["wrong_syncs:NormalsNotRotated", "wrong_syncs:ForgetsModified"] + (
    ["wrong_syncs_pygfx:NormalsUnannounced", "wrong_syncs_pygfx:AnnouncesLastRangeOnly"] if backends.NAME == "pygfx" else [])


def render_verdicts(spec: str, scene: str, params: dict) -> list:
    """Both picture verdicts of every golden frame of ``scene`` drawn with ``params`` by ``spec``, against
    the default goldens and a live reference drawn the same way, under the same-renderer set (the
    tightest: a variant must equal them)."""
    with runner.running(scene, sync.load(spec), **params) as run:
        defaults = scenes.get(scene).defaults
        goldens = [snapshots.load(golden.default_dir(), run.scene, f, params=defaults)
                   for f in scenes.get(scene).frames_with_goldens()]
        return [snapshots.check_render(run, g, sync=spec, here=backends.renderer_info(), override=compare.SAME_RENDERER.name)[0]
                for g in goldens]


def test_there_is_a_variant_with_shared_spheres():
    assert ("mixed_shapes", {"grouping": "by_kind"}) in VARIANTS, VARIANTS


@pytest.mark.parametrize("scene, params", VARIANTS, ids=[f"{s}-{variant_id(p)}" for s, p in VARIANTS])
def test_a_variant_draws_the_default_picture(scene, params):
    records = render_verdicts("reference", scene, params)
    failed = [r for r in records if not r.passed]
    assert not failed, (f"{scene}({params}) drawn by 'reference': {[f'frame {r.frame}: {r.message}' for r in failed]}, "
                        "but should be the default goldens' picture: a golden variant may regroup bodies, not change them")


@pytest.mark.parametrize("spec", SHARED_ONLY)
def test_a_shared_actor_mistake_fails_the_variant_and_only_the_variant(spec):
    default = render_verdicts(spec, "mixed_shapes", {})
    assert all(r.passed for r in default), (f"{spec} on mixed_shapes: {[r.message for r in default if not r.passed]}, but "
                                            "should pass: its mistake is in shared actors, which the default draws none of")
    shared = render_verdicts(spec, "mixed_shapes", {"grouping": "by_kind"})
    assert any(not r.passed for r in shared), f"{spec} on mixed_shapes(grouping='by_kind'): every golden frame passed"


def test_a_variant_naming_no_parameter_is_refused():
    spec = scenes.get("pendulum")
    with pytest.raises(InvalidArgument, match=r"golden_variants has \{'colour': 'red'\}, but 'colour' is not a parameter"):
        SceneSpec(name="p2", title="p2", populate=spec.populate, camera=spec.camera, steps=10, origin="canonical",
                  golden_variants=({"colour": "red"},))
