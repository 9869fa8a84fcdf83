"""The kit's own test session imports every module of the kit before any test runs (``conftest.py``).

``pytester`` drops from ``sys.modules``, when a test that uses it ends, every module imported while it ran,
from any thread: a background run (``background``) that imported a kit module then left two copies of it
in the process, and classes that no longer matched (``perturb.as_dict`` refused ``perturbed.opening``'s
``AfterStep``; measured in a ``./kit test`` on FURY 0.12).
"""

from __future__ import annotations

import pkgutil
import sys

import conformance


def test_every_module_of_the_kit_is_imported_before_the_tests_run():
    modules = [m.name for m in pkgutil.walk_packages(conformance.__path__, "conformance.") if m.name != "conformance.__main__"]
    other_fury = ("conformance.backends.vtk", "conformance.implementations.vtk") if "vtkmodules" not in sys.modules \
        else ("conformance.backends.pygfx", "conformance.implementations.pygfx")
    missing = [m for m in modules if m not in sys.modules and not m.startswith(other_fury)]
    assert len(modules) > 100 and not missing, (
        f"{len(missing)} modules of the kit were not imported by tests/conftest.py before the tests ran, but should "
        f"be (a pytester run would drop and re-import them): {missing[:10]}")
