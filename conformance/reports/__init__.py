"""A run's outputs for people: ``artefacts`` (each image check's pictures and records, kept beside the
run), ``report`` (the HTML page made from those records), ``misplaced`` (a failing vertex check's
picture) and ``screenshot``. Imports ``rendering``, ``sync`` and below (internal)."""
