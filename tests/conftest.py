"""The kit's own tests. ``pytester`` runs the kit end to end in this process; modules with native
extensions cannot be imported twice in one process, so everything the kit imports is imported here,
before pytester snapshots ``sys.modules``."""

import conformance.cli  # noqa: F401
import conformance.compare  # noqa: F401
import conformance.implementations.guide  # noqa: F401
import conformance.pytest_helpers  # noqa: F401
import conformance.runner  # noqa: F401
import conformance.test_scenes  # noqa: F401
import conformance.test_vertices  # noqa: F401
import PIL.Image  # noqa: F401

pytest_plugins = ["pytester"]
