"""Measure both picture verdicts at every golden frame, on the renderer this process has.

``python -m conformance.rendering.measure_reftest [--scenes a,b] [--json PATH]``, once per renderer
(``LIBGL_ALWAYS_SOFTWARE=1 GALLIUM_DRIVER=softpipe python -m …`` and so on: docs/pictures.md). At
each golden frame of each scene it restores the stored state and measures:

* the **renderer verdict** (:func:`conformance.rendering.reftest.renderer_tolerance`): the live
  reference against the golden: pixels differing by more than 2 levels, the other-renderer set's
  outline and shade counts, the set chosen and the verdict;
* the **sync verdict** of the reference sync itself (its run draws frame after frame, the live
  reference from a fresh build): pixels and verdict; it must pass;
* the sync verdict of two drawing errors of one body, made on the reference's drawing after it
  synced (:func:`conformance.rendering.measure_tolerances.perturbed`): moved 2 px across the view, and
  turned 3° in the picture plane (boxes of 40x40 px or more); each must fail. Beside it, the verdict
  the golden alone gave before the live reference (the error's render against the golden, with the
  set the renderer's name chose), to show what the live reference adds;
* the seconds taken by the sync's renders and by the live references.

It prints one line per frame and a summary, and with ``--json`` writes every number.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

__all__ = ["measure_scene", "main"]

ERRORS = ("moved", "turned_in_plane")


def _counts(expected, actual) -> dict[str, int]:
    from conformance.rendering.compare import OTHER_RENDERER, SAME_RENDERER, _differing

    return {"same": int(_differing(expected, actual, SAME_RENDERER.pixel_threshold, SAME_RENDERER.block).sum()),
            "outline": int(_differing(expected, actual, OTHER_RENDERER.pixel_threshold, OTHER_RENDERER.block).sum()),
            "shade": int(_differing(expected, actual, OTHER_RENDERER.shade_threshold, 3).sum())}


def measure_scene(scene_name: str) -> list[dict]:
    """One row of numbers per golden frame of ``scene_name`` (see the module docstring)."""
    from conformance import backends, scenes, sync
    from conformance.sync import runner
    from conformance.errors import GoldenError
    from conformance.rendering import compare, golden, measure_tolerances, reftest, snapshots

    here = backends.renderer_info()
    with scenes.build(scene_name) as built:
        try:
            goldens = {f: snapshots.load(golden.default_dir(), built, f) for f in scenes.get(scene_name).frames_with_goldens()}
        except GoldenError as err:
            raise SystemExit(str(err)) from None
    rows = []
    started = time.perf_counter()
    with runner.running(scene_name, sync.load("reference")) as run:
        drawn, errors = {}, {}
        for frame, g in goldens.items():
            drawn[frame] = snapshots.draw(run, g)
            size = run.scene.image_size
            for kind in ERRORS:
                try:
                    i = measure_tolerances.pick_target(run, size, turning=kind != "moved")
                except LookupError:
                    continue
                with measure_tolerances.perturbed(run, i, kind):
                    errors[frame, kind] = (run.drawing.targets[i].name,
                                           backends.render(run.drawing, run.scene.camera, size))
    sync_seconds = time.perf_counter() - started
    started = time.perf_counter()
    references = reftest.references(scene_name, goldens)
    reference_seconds = time.perf_counter() - started
    for frame, g in goldens.items():
        ref = references[frame]
        chosen, why = reftest.renderer_tolerance(g, ref, here)
        by_name = compare.SAME_RENDERER if golden.same_renderer(g.renderer, here) else compare.OTHER_RENDERER
        row = {"scene": scene_name, "frame": frame,
               "allowed": int(compare.SAME_RENDERER.max_differing_fraction * ref.shape[0] * ref.shape[1]),
               "renderer": {**_counts(g.image, ref), "set": chosen.name, "why": why,
                            "passed": compare.compare_images(g.image, ref, chosen).passed},
               "reference_sync": {**_counts(ref, drawn[frame]),
                                  "passed": compare.compare_images(ref, drawn[frame], compare.SAME_RENDERER).passed}}
        for kind in ERRORS:
            if (frame, kind) not in errors:
                continue
            target, picture = errors[frame, kind]
            row[kind] = {"target": target, **_counts(ref, picture),
                         "passed": compare.compare_images(ref, picture, compare.SAME_RENDERER).passed,
                         "golden_alone": {"set": by_name.name, "passed": compare.compare_images(g.image, picture, by_name).passed}}
        rows.append(row)
    for row in rows:
        row["seconds"] = {"sync_renders": sync_seconds / len(rows), "live_reference": reference_seconds / len(rows)}
    return rows


def _line(row: dict) -> str:
    r = row["renderer"]
    parts = [f"{row['scene']} frame {row['frame']}: renderer {'pass' if r['passed'] else 'FAIL'} ({r['set']}; "
             f"{r['same']} px > 2, outline {r['outline']}, shade {r['shade']})",
             f"reference sync {'pass' if row['reference_sync']['passed'] else 'FAIL'} ({row['reference_sync']['same']} px)"]
    for kind in ERRORS:
        if kind in row:
            e = row[kind]
            parts.append(f"{kind} {'PASSES' if e['passed'] else 'fails'} ({e['same']} px; golden alone, "
                         f"{e['golden_alone']['set']}: {'PASSES' if e['golden_alone']['passed'] else 'fails'})")
    return "; ".join(parts)


def summary(rows: list[dict]) -> str:
    from conformance import backends
    lines = [f"renderer: {backends.renderer_label(backends.renderer_info())}",
             f"frames: {len(rows)}; renderer verdict passed {sum(r['renderer']['passed'] for r in rows)}, sets "
             + ", ".join(f"{s} {sum(r['renderer']['set'] == s for r in rows)}" for s in sorted({r['renderer']['set'] for r in rows}))
             + f"; live reference vs golden: up to {max(r['renderer']['same'] for r in rows)} px > 2, outline "
             f"{max(r['renderer']['outline'] for r in rows)}, shade {max(r['renderer']['shade'] for r in rows)}",
             f"reference sync: passed {sum(r['reference_sync']['passed'] for r in rows)} of {len(rows)}, up to "
             f"{max(r['reference_sync']['same'] for r in rows)} px apart from the live reference"]
    for kind in ERRORS:
        cases = [r[kind] for r in rows if kind in r]
        if cases:
            lines.append(f"{kind}: fails the sync verdict on {sum(not c['passed'] for c in cases)} of {len(cases)} frames "
                         f"({min(c['same'] for c in cases)}–{max(c['same'] for c in cases)} px, "
                         f"{min(r['allowed'] for r in rows)} allowed); "
                         f"the golden alone failed it on {sum(not c['golden_alone']['passed'] for c in cases)} of {len(cases)}")
    sync_s = sum(r["seconds"]["sync_renders"] for r in rows)
    ref_s = sum(r["seconds"]["live_reference"] for r in rows)
    lines.append(f"seconds: the reference's run with its error renders {sync_s:.1f}, the live references {ref_s:.1f}")
    return "\n".join(lines)


def main(argv=None) -> int:
    from conformance import scenes
    from conformance.backends.display import virtual_display

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", default=",".join(scenes.names()))
    parser.add_argument("--json", default="")
    args = parser.parse_args(argv)
    rows = []
    with virtual_display():
        for scene in [s for s in args.scenes.split(",") if s]:
            for row in measure_scene(scene):
                rows.append(row)
                print(_line(row), flush=True)
    print(summary(rows))
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
