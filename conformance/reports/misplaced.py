"""A failing vertex check in the report: the sync's drawing of the failing frame, with pyBullet's outline.

When a check finds targets drawn out of tolerance, :func:`note` renders the frame as the sync drew
it, from the scene's camera, with the outline of every failing target where pyBullet has it
(:mod:`.outline`), and keeps it on the check's node with an :class:`~.records.ImageCheck` of kind
``vertices`` (its message, the worst error against its tolerance, the diagnosis, the failing targets
and the ``reproduce:`` command). The plugin writes it with the run's other pictures when the check's
report says it failed (:func:`keep`), so ``report.html`` shows vertex failures beside the image checks.

What it costs and when: one render and one pyBullet segmentation per kept picture. Default mode keeps
the last failure of a check (under Hypothesis only the final replay of the reported example, not the
examples tried while shrinking); survey mode keeps the first. A picture that cannot be made (no
display, a renderer error) is left out: the check's verdict and message never depend on it.
"""

from __future__ import annotations

from typing import Any, Sequence

import pytest

from conformance.rendering.records import ImageCheck

__all__ = ["PICTURE", "keep", "note"]

#: Where a check's node keeps (record, pictures) of its failing frame until its report is made.
PICTURE = pytest.StashKey[tuple]()


def _final_example() -> bool:
    """False while Hypothesis tries or shrinks examples; True on the final replay and outside Hypothesis."""
    try:
        from hypothesis import control

        if not control.currently_in_test_context():
            return True
        return bool(getattr(control.current_build_context(), "is_final", True))
    except Exception:  # noqa: BLE001  (an unknown Hypothesis: keep the picture)
        return True


def note(node, run, failures: Sequence[Any], worst, *, sync: str, message: str, first: bool) -> None:
    """Keep on ``node`` the picture and record of ``run``'s failing frame: ``failures`` are its failing
    vertex results, ``worst`` the one ``message`` (the check's failure text) is about. ``first``: keep
    only the first failure of the check (survey mode)."""
    if node is None or (first and PICTURE in node.stash) or not _final_example():
        return
    from conformance.bullet import events as events_module
    from conformance.sync.printed import reproduce_command
    from conformance.rendering import golden, outline

    names = sorted({r.target for r in failures})
    try:
        picture = outline.outlined(run, names)
    except Exception:  # noqa: BLE001  (a courtesy: the failure stands without its picture)
        return
    lines = message.splitlines()
    record = ImageCheck(
        kind="vertices", scene=run.scene.name, frame=worst.frame, passed=False,
        message=lines[0] if lines else "",
        metrics={"error_m": float(worst.error)}, limits={"error_m": float(worst.tolerance)},
        details={"diagnosis": next((line[len("diagnosis: "):] for line in lines if line.startswith("diagnosis: ")), ""),
                 "targets_out_of_tolerance": names[:200],
                 **({"events": events_module.dumps(run.events)} if run.events else {})},
        sync=sync, params=golden.jsonable(dict(run.params)),
        reproduce=reproduce_command(run.scene.name, sync, worst.frame, run.params, run.events),
        nodeid=getattr(node, "nodeid", ""))
    node.stash[PICTURE] = (record, {"outlined": picture})


def keep(item, report, pictures) -> None:
    """Write the picture :func:`note` kept on ``item`` when its call ``report`` failed (``pictures``:
    the session's :class:`conformance.checks.image_options.Pictures`); forget it either way."""
    kept = item.stash.get(PICTURE, None)
    if kept is None:
        return
    del item.stash[PICTURE]
    if report.when == "call" and report.failed:
        record, images = kept
        pictures.keep(record, images)
