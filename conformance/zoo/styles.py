"""The ways users draw a pyBullet model, each a style the zoo writes programs in (:mod:`conformance.zoo.programs`).

A style fixes the three choices a program makes: how it draws (``drawing``: one actor per link posed by
its position and rotation; one actor per visual shape posed by a matrix; every body in one shared actor
whose vertices it rewrites; FURY 2's impostor spheres for the sphere shapes), how its bodies move
(``drive``: position or velocity motors before the step, kinematic playback by ``resetJointState`` after
it), and how it loads them (``useFixedBase``, ``globalScaling``, ``URDF_MERGE_FIXED_LINKS``, colours
changed with ``changeVisualShape``, one link made invisible with alpha 0 and left undrawn). Each is a
right program: what it draws is what pyBullet holds when it draws.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["STYLES", "Style", "applicable"]


@dataclass(frozen=True)
class Style:
    name: str
    description: str
    drawing: str            # "links", "shapes", "shared", "impostors"
    drive: str = "position"  # "position", "velocity", "playback"
    fixed_base: bool = False
    scaling: float = 1.0
    merged: bool = False
    recoloured: bool = False
    backends: tuple = ("vtk", "pygfx")


STYLES = {s.name: s for s in (
    Style("links", "one actor per link built from its visual shapes, posed by position and rotation; joints on "
          "position motors", "links"),
    Style("shapes", "one actor per visual shape, posed by a 4x4 matrix (link frame times visual frame); joints on "
          "velocity motors", "shapes", drive="velocity"),
    Style("shared", "every body in one shared actor whose vertices are rewritten after each step; joints on "
          "position motors", "shared"),
    Style("playback", "a fixed base whose joints play a trajectory back with resetJointState after each step, "
          "one actor per link", "links", drive="playback", fixed_base=True),
    Style("fixed", "useFixedBase=True, one actor per visual shape posed by a matrix, joints on position motors",
          "shapes", fixed_base=True),
    Style("scaled", "globalScaling=1.6, one actor per link", "links", scaling=1.6),
    Style("merged", "URDF_MERGE_FIXED_LINKS, one actor per visual shape", "shapes", merged=True),
    Style("recoloured", "colours changed with changeVisualShape, the last link of each body with more than one made "
          "invisible (alpha 0) and not drawn; one actor per visual shape", "shapes", recoloured=True),
    Style("impostors", "FURY 2's default sphere (an impostor) for every sphere shape, one actor per link for the "
          "rest", "impostors", backends=("pygfx",)),
)}


def applicable(style: Style, survey, backend: str) -> str:
    """Why ``style`` cannot be written for the model of ``survey`` on ``backend``; "" when it can."""
    loader = {".sdf": "loadSDF", ".xml": "loadMJCF"}.get(survey.model[survey.model.rfind("."):], "loadURDF")
    if survey.unusable:
        return survey.unusable
    if backend not in style.backends:
        return f"FURY {'0.12' if backend == 'vtk' else '2'} has no such drawing"
    if style.drive == "playback" and not survey.movable:
        return "no joint to play back"
    if style.fixed_base and (loader != "loadURDF" or not survey.movable):
        return "useFixedBase is loadURDF's, for a model with joints"
    if style.scaling != 1.0 and loader == "loadMJCF":
        return "loadMJCF takes no globalScaling"
    if style.merged and (loader != "loadURDF" or not survey.fixed_joints):
        return "URDF_MERGE_FIXED_LINKS merges a URDF's fixed joints, and it has none"
    if style.drawing == "impostors" and not survey.spheres:
        return "no sphere to draw as an impostor"
    return ""
