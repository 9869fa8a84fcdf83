"""Golden snapshots: what reaches the screen is the committed picture of the physics.

Every reference scene has goldens at its first frame, one in the middle of the action and its last
(``golden/<scene>/frame-NNNN.png``, made by ``python -m conformance regen``), each with a manifest
holding the physics state of that frame. Each golden gets two verdicts, reported separately:

* ``test_golden_render``: restore the stored physics state, let the sync under test draw it, render;
  then judge that picture against a live reference (the ``reference`` sync drawing the same state on
  this renderer) with the same-renderer set, the *sync* verdict, and the live reference against the
  golden, the *renderer* verdict (:mod:`conformance.rendering.reftest`). Both are reported apart; the
  check fails if either does. Independent of any drift in physics. The frames are restored in order in
  one run, so data changed without telling the renderer, a frame drawn late, recoloured bodies or a
  moved camera all show.
  A scene's golden variants (``SceneSpec.golden_variants``: the same bodies grouped into shared
  actors, e.g. ``test_golden_render[mixed_shapes-by_kind]``) are judged against the same goldens, the
  live reference drawn through the variant's actors too: grouping changes how a sync must write and
  announce, never what the picture shows.
* ``test_golden_physics``: the live run's state at each golden frame against the stored one: a
  failure here is pyBullet or the platform, not rendering. Past a scene's chaotic step (the wrecking
  ball's whip) a difference is reported as a warning, not hidden and not failed.
* ``test_no_stale_goldens``: every file in a golden directory is a golden some check reads; one no
  check reads (a scene renamed or removed, a frame no longer golden) would pass for coverage it does
  not give. ``python -m conformance regen --prune`` deletes exactly those.
"""

from __future__ import annotations

import shlex
import warnings

import pytest

from conformance import scenes
from conformance.errors import GoldenError
from conformance.checks.pytest_helpers import each_golden_variant, each_scene, variant_id
from conformance.judge import diagnosis


def _reproduce(check: str, scene: str, sync: str, variant: dict | None = None, pictures=None) -> str:
    """The pytest command that runs this check again, with the options of this run that change its
    verdict: the user's scenes, and the golden directory and image tolerance given."""
    import os

    from conformance.sync.printed import rerun_check

    # The whole id, brackets included: "mixed_shapes" alone would select its variants' checks too.
    selected = f"{check}[{scene}-{variant_id(variant)}]" if variant else f"{check}[{scene}]"
    given = []
    if pictures is not None and pictures.golden_dir is not None:
        given += ["--conformance-golden-dir", os.path.relpath(pictures.golden_dir)]
    if pictures is not None and pictures.override:
        given += ["--conformance-image-tolerance", pictures.override]
    return rerun_check(selected, scene, sync, given=given)


def _goldens(pictures, scene, params=None):
    from conformance.rendering import snapshots

    try:
        return {frame: snapshots.load(pictures.golden_dir_for(scene.name), scene, frame, params=params)
                for frame in scenes.get(scene.name).frames_with_goldens()}
    except GoldenError as err:
        problem = str(err)
    # Failed outside the except: inside, pytest printed the paragraph twice, joined by "During handling
    # of the above exception, another exception occurred".
    pytest.fail(problem, pytrace=False)


@each_golden_variant()
def test_golden_render(scene_name, variant, kit, pictures, request):
    """Each golden frame, restored and drawn by the sync under test, renders as the ``reference`` sync
    draws the same state on this renderer (the sync verdict, same-renderer set), and that live
    reference renders as the golden (the renderer verdict): :mod:`conformance.rendering.reftest`. In a
    golden variant both draw through the variant's shared actors."""
    from conformance.rendering import reftest, snapshots

    if pictures.regen and not variant:  # a variant has no goldens of its own to make
        try:
            pictures.note_regenerated(request.node, snapshots.regenerate(scene_name, pictures.golden_dir_for(scene_name)))
        except GoldenError as err:
            refused = str(err)
        else:
            refused = ""
        if refused:
            pytest.fail(refused, pytrace=False)
    with kit.run(scene_name, **variant) as run:
        goldens = _goldens(pictures, run.scene, scenes.get(scene_name).defaults)
        physics = {v.frame: v for v in snapshots.check_physics(scene_name, goldens)}
        drawn = {frame: snapshots.draw(run, golden) for frame, golden in goldens.items()}
        # A soft body drawn as a rigid one (a sync written before soft bodies) is named before any picture.
        soft = diagnosis.soft_drawn_as_rigid(run, kit.tolerance)
    # Drawn after the sync's run is closed: one live scene at a time, as an application has.
    references = reftest.references(scene_name, goldens, variant)
    failures, blamed = [], []
    for frame, golden in goldens.items():
        record, images = reftest.judge(golden, drawn[frame], references[frame], here=pictures.renderer,
                                       override=pictures.override, sync=kit.sync)
        if "difference" in images and not blamed:  # the sync's verdict failed: name the bodies, once
            from conformance.sync.printed import reproduce_command

            blamed = [f"{reftest.bodies_where_pixels_differ(scene_name, golden, variant, references[frame], drawn[frame])}"
                      f" [{scene_name}, frame {frame}]; the vertices, frame by frame (a mistake there is named): "
                      f"{reproduce_command(scene_name, kit.sync, max(frame, 1), variant, tolerance=kit.tolerance)}"]
        record.details["physics"] = physics[frame].as_dict()
        record.reproduce = _reproduce("test_golden_render", scene_name, kit.sync, variant, pictures)
        record.nodeid = request.node.nodeid
        pictures.keep(record, images)
        request.node.user_properties.append((reftest.GOLDEN_VERDICTS, {"frame": frame, **record.details["verdicts"]}))
        if not record.passed:
            failures.append(record)
    if failures:
        where = f"{scene_name}({', '.join(f'{k}={v!r}' for k, v in variant.items())})" if variant else scene_name
        # Each frame's two verdicts, the failed one first: what the sync did apart from what the renderer did.
        lines = [f"{line} [{where}, frame {r.frame}, sync {kit.sync!r}]" for r in failures
                 for line in sorted(r.message.splitlines(), key=lambda line: " FAIL: " not in line)]
        if soft:
            lines.insert(1, soft)
        lines += blamed
        lines.append(f"pictures: {pictures.results} (report.html); reproduce: {failures[0].reproduce}")
        pytest.fail("\n".join(lines), pytrace=False)


@each_scene()
def test_golden_physics(scene_name, pictures):
    """The live run's physics state at each golden frame is the stored one (within 1 µm / 1e-5 rad)."""
    from conformance.rendering import snapshots

    with scenes.build(scene_name) as scene:
        goldens = _goldens(pictures, scene)
    verdicts = snapshots.check_physics(scene_name, goldens)
    failed = [v for v in verdicts if not v.difference.ok and not v.chaotic]
    for v in verdicts:
        if not v.difference.ok and v.chaotic:
            warnings.warn(f"{scene_name} frame {v.frame} (past its chaotic step {scenes.get(scene_name).chaotic_after}): "
                          f"physics differs from the golden's stored state, {v.difference.describe()}; its picture "
                          "verdicts restore the stored state and stay valid")
    if failed:
        from conformance.sync import own_scenes
        from conformance.rendering import golden

        # A user's scene most likely changed itself (a body moved, a mass changed); the kit's scenes are
        # fixed, so for them the difference is pyBullet's or the platform's.
        source = own_scenes.source_of(scene_name)
        cause = (f"the scene changed (its populate in {own_scenes.scene_arguments(scene_name)[1]}), or pyBullet or the "
                 "platform did. If you changed the scene on purpose" if source is not None else
                 "this is pyBullet or the platform. If pyBullet changed on purpose")
        command = golden.regen_command(scene_name, pictures.golden_dir_for(scene_name))
        pytest.fail("\n".join(f"physics differs from the golden's stored state at {scene_name} frame {v.frame}: "
                              f"{v.difference.describe()}. The picture verdicts are unaffected (they restore the stored "
                              f"state); {cause}, make its goldens anew: {command}" for v in failed), pytrace=False)


def test_no_stale_goldens(pictures):
    """Every file in the golden directories of this run's scenes is a golden that a check reads."""
    from conformance.rendering import golden

    found = [path for paths in golden.stale_by_directory(pictures.golden_dir_for).values() for path in paths]
    if found:
        from conformance.sync import own_scenes, printed

        given = ["--golden-dir", str(pictures.golden_dir)] if pictures.golden_dir is not None else []
        # the run's own scenes too: without them regen sees only the kit's, and would take their goldens for stale
        sources = dict.fromkeys(w for name in scenes.names() for w in own_scenes.scene_arguments(name)[1:])
        given += [w for source in sources for w in ("--scenes", source)]
        pytest.fail(f"{len(found)} file(s) in the golden directories are read by no check (a scene removed or renamed, "
                    f"a frame no longer golden, a stray file): {', '.join(map(str, found[:20]))}"
                    + (f" and {len(found) - 20} more" if len(found) > 20 else "")
                    + f". Delete exactly those with: {shlex.join([printed.python(), '-m', 'conformance', 'regen', '--prune', *given])}",
                    pytrace=False)
