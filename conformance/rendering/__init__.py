"""Pictures: golden snapshots, image comparison, the check against pyBullet's own renderer.

Nothing here imports pytest: the plugin and the command line both use these modules, and every
comparison returns an :class:`~conformance.rendering.records.ImageCheck` record that the plugin turns
into pass/fail and :mod:`conformance.reports.report` turns into a page. Renders come from the
backend (:mod:`conformance.backends`), never from VTK or pygfx directly.

* ``records``: the result record of an image check;
* ``compare``: image against image, within a tolerance set (``same-renderer``, ``other-renderer``);
* ``golden``: golden PNGs and their manifests: reading, validating, writing;
* ``snapshots``: making goldens, the render and physics verdicts on them, regeneration;
* ``reftest``: a golden's two picture verdicts: the sync's render against a live reference render
  (the sync verdict) and that reference against the golden (the renderer verdict);
* ``silhouettes``: each target's FURY silhouette against pyBullet's segmentation mask;
* ``framing``: every body of a scene inside the picture and large enough to judge;
* ``outline``: where pyBullet has a body, drawn over a picture;
* ``images``, ``animation``: picture helpers; a run as frames and a GIF (``render --gif``);
* ``measure_tolerances``, ``measure_reftest``, ``measure_silhouettes``: the measurements behind the
  tolerances (``python -m conformance.rendering.measure_…``: entry points, public).

Imports ``sync``, ``judge``, ``backends``, ``scenes``, ``bullet`` and the shared leaves; the camera as
matrices is :mod:`conformance.backends.projection`, a run's outputs are :mod:`conformance.reports`.
"""
