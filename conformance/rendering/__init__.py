"""Pictures: golden snapshots, image comparison, the check against pyBullet's own renderer, reports.

Nothing here imports pytest: the plugin and the command line both use these modules, and every
comparison returns an :class:`~conformance.rendering.records.ImageCheck` record that the plugin turns
into pass/fail and :mod:`conformance.rendering.report` turns into a page.

* ``records``: the result record of an image check;
* ``compare``: image against image, within a tolerance set (``same-renderer``, ``other-renderer``);
* ``projection``: the scene camera as view and projection matrices, for VTK and pyBullet alike;
* ``silhouettes``: each target's FURY silhouette against pyBullet's segmentation mask;
* ``golden``: golden PNGs and their manifests: reading, validating, writing atomically;
* ``artefacts``, ``report``: failure images on disk and the HTML page over a run's records.
"""
