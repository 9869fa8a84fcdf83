"""Is every body on screen and large enough to be judged? The framing check of a scene's camera.

Pictures only prove something about bodies they show: a body outside the picture, cut by its edge or
by a clipping plane, or a few pixels across, passes any image check whatever the sync does. This check
projects each target's world vertices (what the renderer will draw, :func:`conformance.backends.world_vertices`)
through the camera (:func:`.projection.project`) and requires every vertex inside the picture and
between the clipping planes, and the target's projected extent (the larger of its width and height on
screen) to be at least ``min_extent`` pixels. It uses no renderer, so it says exactly which target is
off by how much.
"""

from __future__ import annotations

from typing import Collection


from conformance.backends import projection
from conformance.rendering.records import ImageCheck

__all__ = ["EXCEPTIONS", "MIN_EXTENT", "framing", "of_scene"]

#: Targets of the kit's scenes the framing check excuses, and why.
EXCEPTIONS = {
    # Placed 50 m away on purpose, to test precision far from the origin; no camera shows both.
    "tumbling": {"may_leave": {"far_box"}},
    # The rope's pin, a 2 cm box hidden by the first disc / link: a dot at any camera showing the rope.
    "chain": {"may_be_small": {"hinge"}},
    "wrecking_ball": {"may_be_small": {"hinge"}},
}

#: The smallest projected extent, in pixels, a target may have: below it a body is a dot whose
#: position and turn no picture can judge.
MIN_EXTENT = 3.0


def framing(drawing, camera, size, *, min_extent: float = MIN_EXTENT, margin: float = 0.0,
            may_be_small: Collection[str] = (), may_leave: Collection[str] = (), scene: str = "",
            frame: int = 0) -> ImageCheck:
    """Every target of ``drawing`` inside the ``size = (width, height)`` picture of ``camera`` (at least
    ``margin`` pixels from each edge), in front of the near and behind the far clipping plane, and at
    least ``min_extent`` pixels across. ``details["targets"]`` lists each target's box on screen
    ``[x0, y0, x1, y1]``, its extent and depth range, and what is wrong with it.

    Exceptions, each reported in the target's row: a static body (mass 0: a ground, a plate) is scenery
    larger than any picture, so it need only reach into the picture and
    the clipping range, not fit in them; targets named in
    ``may_leave`` need not be in the picture at all (a body placed far away on purpose), and those in
    ``may_be_small`` need not be ``min_extent`` across (a pin hidden in what hangs from it)."""
    from conformance import backends

    width, height = size
    near, far = camera.clipping_range
    rows, problems = [], []
    for target in drawing.targets:
        points = backends.world_vertices(target.actor)[target.start:target.stop]
        pixels, depth = projection.project(camera, size, points)
        static = drawing.world.p.getDynamicsInfo(target.body, target.link)[0] == 0
        row = {"target": target.name, "depth": [float(depth.min()), float(depth.max())], "static": bool(static)}
        wrong = []
        if target.name in may_leave:
            row.update(problems=[], exempt="may leave the picture")
            rows.append(row)
            continue
        if (depth.max() < near or depth.min() > far) if static else (depth.min() < near or depth.max() > far):
            wrong.append(f"depth {depth.min():.3g}..{depth.max():.3g} m leaves the clipping range {near:g}..{far:g} m")
        if depth.min() > 0:
            x0, y0 = pixels.min(axis=0)
            x1, y1 = pixels.max(axis=0)
            extent = float(max(x1 - x0, y1 - y0))
            row.update(box=[float(x0), float(y0), float(x1), float(y1)], extent=extent)
            out = {"left": margin - x0, "top": margin - y0, "right": x1 - (width - margin),
                   "bottom": y1 - (height - margin)}
            cut = {side: amount for side, amount in out.items() if amount > 0}
            if static and x0 < width and x1 > 0 and y0 < height and y1 > 0:
                cut = {}  # scenery: it reaches into the picture, and that is all a ground can do
            if cut:
                wrong.append("cut by the picture's " + ", ".join(f"{side} edge by {amount:.1f} px"
                                                                 for side, amount in cut.items()))
            if extent < min_extent and target.name not in may_be_small:
                wrong.append(f"only {extent:.2f} px across, but should be at least {min_extent:g} px")
        row["problems"] = wrong
        rows.append(row)
        if wrong:
            problems.append(f"{target.name!r}: {'; '.join(wrong)}")
    smallest = min((r["extent"] for r in rows if "extent" in r), default=float("nan"))
    where = f"[{scene}, frame {frame}, camera {camera.as_dict()}, {width}x{height}]"
    if problems:
        message = f"{len(problems)} of {len(rows)} targets badly framed: " + " | ".join(problems[:5]) + f" {where}"
    else:
        message = f"all {len(rows)} targets inside the picture, smallest {smallest:.1f} px across {where}"
    return ImageCheck(kind="framing", scene=scene, frame=frame, passed=not problems, message=message,
                      metrics={"smallest_extent": smallest, "badly_framed": float(len(problems))},
                      limits={"smallest_extent": float(min_extent), "badly_framed": 0.0},
                      details={"targets": rows, "camera": camera.as_dict(), "size": list(size)})


def of_scene(drawing, camera, size, *, scene: str, frame: int) -> ImageCheck:
    """:func:`framing` of a scene's picture with the scene's exceptions (:data:`EXCEPTIONS`)."""
    return framing(drawing, camera, size, scene=scene, frame=frame, **EXCEPTIONS.get(scene, {}))
