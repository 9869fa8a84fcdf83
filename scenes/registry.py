"""The registry of reference scenes and the one way to build them."""

from __future__ import annotations

import importlib
import inspect
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping

from conformance.errors import InvalidArgument

from .base import Camera, Scene

__all__ = ["SCENES", "SceneSpec", "build", "get", "names", "register"]

# One module per scene; order is the order of reports and of the README.
_MODULES = (
    "ball_collision",
    "brick_wall",
    "brick_wall_single",
    "chain",
    "wrecking_ball",
    "domino",
    "free_fall",
    "sliding_box",
    "bouncing_ball",
    "pendulum",
    "mixed_shapes",
    "weighted",
    "tumbling",
    "crossing",
    "cloth",
    "soft_ball",
    "jelly",
)


@dataclass(frozen=True)
class SceneSpec:
    """How to build one scene: ``populate(scene, **params)`` adds its bodies, bindings and actions.

    ``defaults`` are read from ``populate``'s keyword-only parameters, so the signature is the one
    place a parameter and its default are written. ``parameters`` returns a Hypothesis strategy of
    parameter dicts that keep the scene meaningful (used by the property-based checks).
    """

    name: str
    title: str
    populate: Callable[..., None]
    camera: Camera
    steps: int
    origin: str  # "guide" or "canonical"
    description: str = ""
    image_size: tuple[int, int] = (450, 384)
    parameters: Callable[[], Any] | None = None
    gravity: tuple[float, float, float] = (0.0, 0.0, -10.0)
    poster_step: int | None = None  # the frame that shows the scene best (README thumbnails); else `steps`
    #: Frames with golden snapshots: the first, one in the middle of the action (the poster frame,
    #: else half-way) and the last, unless the scene names its own.
    golden_frames: tuple[int, ...] | None = None
    #: The step after which the scene's physics is chaotic (a whip, a pile): small platform
    #: differences in floating point grow there, so a golden's stored physics state may not be
    #: reproduced on another machine. None: the scene is expected to reproduce everywhere.
    chaotic_after: int | None = None
    #: Parameter sets the property-based checks always try, besides the defaults: the variants that
    #: exercise a different drawing path (e.g. shared actors) and must not be left to chance.
    examples: tuple[Mapping[str, Any], ...] = ()
    #: Parameter sets that draw the default picture another way (bodies sharing one actor, their
    #: vertices rewritten): each gets the golden render verdict against the default goldens, so what a
    #: sync fails to upload from a shared actor shows in a picture. A variant may change how bodies are
    #: grouped into actors, never a body or its pose: its reference picture must be the default's
    #: within the same-renderer tolerance (``tests/test_golden_variants.py`` keeps that true).
    golden_variants: tuple[Mapping[str, Any], ...] = ()
    #: The world is reset with ``RESET_USE_DEFORMABLE_WORLD`` before anything is built: soft bodies need it.
    deformable: bool = False
    defaults: Mapping[str, Any] = field(init=False)

    def __post_init__(self):
        params = inspect.signature(self.populate).parameters.values()
        defaults = {p.name: p.default for p in params if p.kind is inspect.Parameter.KEYWORD_ONLY}
        object.__setattr__(self, "defaults", defaults)
        for argument in ("examples", "golden_variants"):
            for example in getattr(self, argument):
                unknown = sorted(set(example) - set(defaults))
                if unknown:
                    raise InvalidArgument(f"SceneSpec {self.name!r}: {argument} has {example!r}, but "
                                          f"{', '.join(map(repr, unknown))} is not a parameter of its populate()")

    def frames_with_goldens(self) -> tuple[int, ...]:
        if self.golden_frames is not None:
            return tuple(self.golden_frames)
        middle = self.poster_step if self.poster_step is not None else self.steps // 2
        return tuple(sorted({0, middle, self.steps}))

    def build(self, **params: Any) -> Scene:
        unknown = sorted(set(params) - set(self.defaults))
        if unknown:
            raise InvalidArgument(
                f"scene {self.name!r} has no parameter {', '.join(map(repr, unknown))}; "
                f"its parameters are {', '.join(self.defaults) or '(none)'}"
            )
        full = {**self.defaults, **params}
        scene = Scene(
            name=self.name,
            params=full,
            camera=self.camera,
            image_size=self.image_size,
            steps=self.steps,
            description=self.description,
            deformable=self.deformable,
        )
        try:
            scene.p.setGravity(*self.gravity)
            self.populate(scene, **full)
            if not scene.bindings:
                raise InvalidArgument(f"scene {self.name!r} with {full} has nothing to draw")
        except BaseException:
            scene.close()
            raise
        return scene


def _load() -> dict[str, SceneSpec]:
    specs = {}
    for module in _MODULES:
        spec = importlib.import_module(f"{__package__}.{module}").SPEC
        specs[spec.name] = spec
    return specs


SCENES: dict[str, SceneSpec] = _load()


def register(spec: SceneSpec) -> SceneSpec:
    """Add a scene of your own; register it before the checks are collected (e.g. in a conftest.py),
    since checks are parametrized over the registry at import."""
    if not isinstance(spec, SceneSpec):
        raise InvalidArgument(f"spec={spec!r} ({type(spec).__name__}), but should be a SceneSpec")
    if spec.name in SCENES:
        raise InvalidArgument(f"spec.name={spec.name!r} is already registered")
    SCENES[spec.name] = spec
    return spec


def names(origin: str | None = None) -> list[str]:
    return [name for name, spec in SCENES.items() if origin in (None, spec.origin)]


def get(name: str) -> SceneSpec:
    try:
        return SCENES[name]
    except KeyError:
        raise InvalidArgument(f"scene={name!r}, but should be one of: {', '.join(SCENES)}") from None


def build(name: str, **params: Any) -> Scene:
    """Build scene ``name`` with ``params`` over its defaults; the caller must close it."""
    return get(name).build(**params)
