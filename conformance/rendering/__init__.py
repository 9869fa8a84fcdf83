"""Pictures: golden snapshots, image comparison, the check against pyBullet's own renderer, reports.

Nothing here imports pytest: the plugin and the command line both use these modules, and every
comparison returns an :class:`~conformance.rendering.records.ImageCheck` record that the plugin turns
into pass/fail and :mod:`conformance.rendering.report` turns into a page. Renders come from the
backend (:mod:`conformance.backends`), never from VTK or pygfx directly.

* ``records``: the result record of an image check;
* ``compare``: image against image, within a tolerance set (``same-renderer``, ``other-renderer``);
* ``golden``: golden PNGs and their manifests: reading, validating, writing;
* ``snapshots``: making goldens, the render and physics verdicts on them, regeneration;
* ``reftest``: a golden's two picture verdicts: the sync's render against a live reference render
  (the sync verdict) and that reference against the golden (the renderer verdict);
* ``projection``: the scene camera as view and projection matrices, for both FURYs and pyBullet alike;
* ``silhouettes``: each target's FURY silhouette against pyBullet's segmentation mask;
* ``framing``: every body of a scene inside the picture and large enough to judge;
* ``artefacts``, ``report``, ``screenshot``: failure pictures on disk, the HTML page over a run's
  records, and a picture of that page (headless Chromium);
* ``measure_tolerances``: the measurements behind the tolerance sets (``docs/image-tolerances.md``).
"""
