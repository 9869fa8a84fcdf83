"""The checks' toolkit (the check files ``conformance/test_*.py`` are its users): assertions and the
``kit`` fixture's object (``pytest_helpers``), survey mode (``survey``), one scene run shared between
checks (``shared_run``), the image checks' options (``image_options``), the physics laws' assertions
(``physics_assertions``), Hypothesis strategies and profiles (``strategies``, ``profiles``), determinism
across processes (``determinism``) and the documented behaviour list (``documented``). Imports
``reports``, ``rendering``, ``sync``, ``judge`` and below (internal)."""
