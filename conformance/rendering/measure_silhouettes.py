"""Measure the silhouette check over every scene's parameter space: the numbers behind its bounds.

``python -m conformance.rendering.measure_silhouettes [--draws N] [--scenes a,b] [--seed S] [--out FILE.md]``
draws, per scene, ``N`` random parameter sets (the scene's own strategy), run lengths (0-60 frames) and,
for half of them, turns of every body and joint before the first sync (as the orientation check does);
runs the reference sync there, and compares FURY's silhouettes with pyBullet's
(:func:`conformance.rendering.silhouettes.compare_silhouettes`, the checks' own thresholds). It writes,
per shape kind and size on screen, how many targets were judged, the worst use of the pixels-off bound
and where, and every draw that failed: a right sync's failures are false alarms. Issue 28's numbers
(docs/precision.md) are this command's, before and after the bounds of small bodies and spheres.
"""

from __future__ import annotations

import argparse
import sys

__all__ = ["measure", "markdown"]

BUCKETS = ((50, "50-99 px"), (100, "100-299 px"), (300, "300-999 px"), (1000, "1,000 px and more"))


def _bucket(pixels: int) -> str:
    return [name for low, name in BUCKETS if pixels >= low][-1]


def measure(scene_names, draws: int, seed: int = 0, keep=None) -> list[dict]:
    """One row per target judged in each draw: scene, draw, kind, pixels, pixels off, allowed, passed.
    With ``keep`` (a directory), each failing draw's masks are written there (``mask_images``), with its turns."""
    from hypothesis import HealthCheck, Phase, given, settings, strategies as st
    from hypothesis import seed as seeded

    from conformance import backends, scenes, sync
    from conformance.checks import strategies
    from conformance.sync import runner
    from conformance.bullet.events import turning_everything
    from conformance.rendering import silhouettes

    reference = sync.load("reference")
    rows: list[dict] = []
    for scene_name in scene_names:
        @seeded(seed)
        @settings(max_examples=draws, database=None, deadline=None, phases=[Phase.generate],
                  suppress_health_check=list(HealthCheck))
        @given(params=strategies.scene_parameters(scene_name), frames=st.integers(0, 60),
               turns=st.one_of(st.just([]), st.lists(strategies.orientations(), min_size=1, max_size=4)))
        def draw(params, frames, turns):
            events = ()
            if turns:
                with scenes.build(scene_name, **params) as probe:
                    events = turning_everything(len({b.body for b in probe.rigid}), turns)
            with runner.running(scene_name, reference, events=events, **params) as run:
                run.advance(frames)
                scene = run.scene
                if not silhouettes.pybullet_draws_it(scene, run.frame):
                    return
                fury = backends.render_ids(run.drawing, scene.camera, scene.image_size)
                bullet = silhouettes.pybullet_mask(scene, scene.bindings, scene.camera, scene.image_size)
                record = silhouettes.compare_silhouettes(
                    fury, bullet, min_iou=silhouettes.thresholds(scene.bindings), rounding=silhouettes.roundings(scene.bindings),
                    discs=silhouettes.projected_discs(scene, scene.bindings, scene.camera, scene.image_size),
                    radii=silhouettes.projected_radii(scene, scene.bindings, scene.camera, scene.image_size),
                    names=[t.name for t in run.drawing.targets], scene=scene_name, frame=run.frame,
                    touching=silhouettes.touching_pairs(scene, scene.bindings, fury, bullet))
                where = f"{scene_name}({', '.join(f'{k}={v!r}' for k, v in params.items())}), frame {run.frame}" + (
                    f", {len(turns)} turns" if turns else "")
                if keep is not None and not record.passed:
                    _keep(keep, len(rows), fury, bullet, where, turns)
                for t in record.details["targets"]:
                    rows.append({"scene": scene_name, "where": where, "target": t["target"],
                                 "kind": scene.bindings[t["index"]].shape.kind,
                                 "pixels": max(t["fury_pixels"], t["pybullet_pixels"]), "off": t["off"],
                                 "allowed": t["allowed_off"], "iou": t["iou"], "passed": t["passed"]})

        draw()
        print(f"{scene_name}: {draws} draws", file=sys.stderr, flush=True)
    return rows


def _keep(directory, number: int, fury, bullet, where: str, turns) -> None:
    from pathlib import Path

    from PIL import Image

    from conformance.files import write_atomically
    from conformance.rendering import silhouettes

    folder = Path(directory)
    folder.mkdir(parents=True, exist_ok=True)
    for name, image in silhouettes.mask_images(fury, bullet).items():
        Image.fromarray(image).save(folder / f"draw{number}-{name}.png")
    write_atomically(folder / f"draw{number}.txt", f"{where}\nturns: {[list(map(float, q)) for q in turns]}\n".encode())


def markdown(rows: list[dict], *, made_by: str, backend: str) -> str:
    lines = [f"### Silhouettes over the scenes' parameter space, {backend}", "", f"Made by `{made_by}`.", "",
             "| shape | size on screen | targets judged | failed | worst use of the pixels-off bound (pixels off / allowed, where) |",
             "|---|---|---|---|---|"]
    groups: dict[tuple[str, str], list[dict]] = {}
    for row in rows:
        groups.setdefault((row["kind"], _bucket(row["pixels"])), []).append(row)
    order = {name: i for i, (_, name) in enumerate(BUCKETS)}
    for (kind, bucket), found in sorted(groups.items(), key=lambda kv: (kv[0][0], order[kv[0][1]])):
        worst = max(found, key=lambda r: r["off"] / max(r["allowed"], 1))
        failed = sum(not r["passed"] for r in found)
        lines.append(f"| {kind} | {bucket} | {len(found)} | {failed} | {worst['off'] / max(worst['allowed'], 1):.0%} "
                     f"({worst['off']}/{worst['allowed']}, {worst['target']!r} in {worst['where']}) |")
    failures = [r for r in rows if not r["passed"]]
    lines += ["", f"Failed ({len(failures)}):" if failures else "Failed: none.", ""]
    lines += [f"- {r['target']!r} ({r['kind']}, {r['pixels']} px): {r['off']} pixels off, {r['allowed']} allowed, "
              f"IoU {r['iou']:.3f} in {r['where']}" for r in failures[:50]]
    return "\n".join(lines)


def main(argv=None) -> int:
    from conformance import backends, scenes
    from conformance.backends import display
    from conformance.commands.common import emit

    parser = argparse.ArgumentParser(prog="python -m conformance.rendering.measure_silhouettes", description=__doc__.split("\n\n")[0])
    parser.add_argument("--draws", type=int, default=300, help="random draws per scene (default 300)")
    parser.add_argument("--scenes", default=None, help="comma-separated scene names (default: every scene)")
    parser.add_argument("--seed", type=int, default=0, help="the draws' seed (default 0)")
    parser.add_argument("--out", default=None, help="also write the markdown here")
    parser.add_argument("--keep", default=None, metavar="DIR", help="write each failing draw's masks and turns here")
    args = parser.parse_args(argv)
    names = args.scenes.split(",") if args.scenes else scenes.names()
    display.ensure_display()
    rows = measure(names, args.draws, args.seed, args.keep)
    made_by = " ".join(["python -m conformance.rendering.measure_silhouettes", *(argv if argv is not None else sys.argv[1:])])
    emit(markdown(rows, made_by=made_by, backend=backends.describe()), args.out)
    return 1 if any(not r["passed"] for r in rows) else 0


if __name__ == "__main__":
    sys.exit(main())
