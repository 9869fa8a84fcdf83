"""The integration guide's sync recipes for the backend in force: as written for FURY 0.12
(:mod:`conformance.implementations.vtk.guide`), or ported to FURY 2 the way a FURY user ports them
(:mod:`conformance.implementations.pygfx.guide`). The same names on both, so ``--sync guide-actor``
means "the guide's actor recipe" in either environment."""

from __future__ import annotations

import importlib

from conformance import backends

__all__ = ["GuideActorSync", "GuideJointSync", "GuideSync", "GuideVertexSync"]

_module = importlib.import_module(f"conformance.implementations.{backends.NAME}.guide")
GuideActorSync, GuideJointSync, GuideSync, GuideVertexSync = (getattr(_module, name) for name in __all__)
