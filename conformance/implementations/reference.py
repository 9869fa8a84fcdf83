"""The kit's reference sync for the backend in force: ``ReferenceSync`` from
:mod:`conformance.implementations.vtk.reference` (FURY 0.12) or
:mod:`conformance.implementations.pygfx.reference` (FURY 2). One name on both, so that
``--sync reference`` and ``conformance.implementations.reference:ReferenceSync`` mean the same thing
in either environment."""

from __future__ import annotations

import importlib

from conformance import backends

__all__ = ["ReferenceSync"]

ReferenceSync = importlib.import_module(f"conformance.implementations.{backends.NAME}.reference").ReferenceSync
