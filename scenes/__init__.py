"""The kit's reference scenes: the guide's six simulations and small canonical ones.

``build(name, **params)`` returns a live :class:`~scenes.base.Scene`; ``SCENES`` lists them all.
In a checkout this directory is top-level ``scenes/``; the package imports it as
``conformance.scenes`` (``conformance/scenes`` links here), which is also where a wheel installs it.
"""

from __future__ import annotations

from .base import IDENTITY, Binding, Camera, ExternalForce, MovingPivot, Scene, Shape
from .registry import SCENES, SceneSpec, build, get, names, register

__all__ = [
    "IDENTITY",
    "SCENES",
    "Binding",
    "Camera",
    "ExternalForce",
    "MovingPivot",
    "Scene",
    "SceneSpec",
    "Shape",
    "build",
    "get",
    "names",
    "register",
]
