"""Golden snapshots on disk: a PNG and a JSON manifest per scene frame; reading, validating, writing.

Layout: ``<golden dir>/<scene>/frame-<NNNN>.png`` and ``frame-<NNNN>.json`` beside it. The manifest
says how the picture was made (scene, parameters, frame, camera, size, sync, the renderer's OpenGL
strings, library versions) and holds the physics state of that frame (:mod:`conformance.bullet.state`).

Guarantees:

* reading validates everything before anything is compared, and a golden that cannot be used raises
  one :class:`~conformance.errors.GoldenError` paragraph naming the file, what is wrong and the
  command that makes it anew (:func:`regen_command`): a missing PNG or manifest, a file that is not a
  PNG or is truncated, a picture of the wrong size, a malformed manifest, or one made for other
  parameters, another frame or another camera;
* writing is atomic (a temporary file in the same directory, then a rename): a golden is never
  half-written, and concurrent writers (pytest-xdist workers) never see one;
* the bytes depend only on the pixels and the manifest's content: PNGs carry no time or software
  chunks and manifests are JSON with sorted keys, so regenerating an unchanged golden changes no byte.
"""

from __future__ import annotations

import importlib.metadata as md
import io
import json
import os
import shlex
import zlib
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Iterable

import numpy as np

from conformance.errors import GoldenError, GoldenMissing, GoldenUnreadable
from conformance.files import encode_png, write_atomically
from conformance.sync.own_scenes import default_dir  # where a scene's goldens live is own_scenes' to say

__all__ = ["FORMAT", "Golden", "default_dir", "encode_manifest", "jsonable", "library_versions", "paths", "read", "regen_command", "same_renderer", "stale", "stale_by_directory", "write"]

#: The manifest format; bumped when its meaning changes, so an old manifest is refused, not misread.
FORMAT = 1
_REQUIRED = ("format", "scene", "params", "frame", "camera", "size", "sync", "renderer", "versions", "state")


def same_renderer(made_by: dict[str, str], here: dict[str, str]) -> bool:
    """Whether a golden was made by the renderer this machine has: the same backend, library versions
    and GPU (OpenGL strings for VTK, the wgpu adapter for pygfx), every key either side names."""
    return all(made_by.get(k) == here.get(k) for k in set(made_by) | set(here))


def paths(directory: Path | str, scene: str, frame: int) -> tuple[Path, Path]:
    """The PNG and manifest paths of ``scene`` at ``frame``."""
    base = Path(directory) / scene / f"frame-{frame:04d}"
    return base.with_suffix(".png"), base.with_suffix(".json")


def stale(directory: Path | str, wanted: dict[str, Iterable[int]]) -> list[Path]:
    """Every file under ``directory`` that no golden of ``wanted`` (scene → its golden frames) is: a
    scene no longer registered, a frame no longer golden, a stray file. Nothing reads them, so a
    committed one would pass for coverage it does not give."""
    directory = Path(directory)
    if not directory.is_dir():
        return []
    used = {p for scene, frames in wanted.items() for frame in frames for p in paths(directory, scene, frame)}
    return sorted(p for p in directory.rglob("*") if p.is_file() and p not in used)


def stale_by_directory(directory_for: Callable[[str], Path]) -> dict[Path, list[Path]]:
    """:func:`stale` files of every golden directory of the registered scenes (``directory_for(name)``
    says where a scene's goldens live): a directory keeps the goldens of every scene it holds."""
    from conformance import scenes

    wanted: dict[Path, dict[str, Iterable[int]]] = {}
    for name in scenes.names():
        wanted.setdefault(Path(directory_for(name)), {})[name] = scenes.get(name).frames_with_goldens()
    return {directory: stale(directory, frames) for directory, frames in wanted.items()}


def regen_command(scene: str, directory: Path | str | None = None) -> str:
    """The whole command that (re)makes a scene's goldens in ``directory`` (all its frames together:
    they share one run): with ``--scenes`` for a user's scene and ``--golden-dir`` unless ``directory``
    is where the scene's goldens live by default."""
    from conformance.sync import own_scenes, printed

    words = [printed.python(), "-m", "conformance", "regen", scene, *own_scenes.scene_arguments(scene)]
    if directory is not None and Path(directory).resolve() != own_scenes.golden_dir(scene).resolve():
        words += ["--golden-dir", os.path.relpath(Path(directory).resolve())]
    return shlex.join(words)


def library_versions() -> dict[str, str]:
    versions = {}
    for dist in ("vtk", "fury", "pybullet", "numpy", "pygfx", "wgpu"):
        try:
            versions[dist] = md.version(dist)
        except md.PackageNotFoundError:
            if dist not in ("vtk", "pygfx", "wgpu"):  # each FURY's renderer, named only where it is installed
                versions[dist] = "missing"
    return versions


def jsonable(value: Any) -> Any:
    """Parameters as JSON holds them (tuples become lists), for storing and comparing alike."""
    return json.loads(json.dumps(value))


@dataclass(frozen=True)
class Golden:
    """A golden picture, ``(height, width, 3)`` uint8, and its manifest."""

    image: np.ndarray
    manifest: dict[str, Any]
    png: Path

    @property
    def state(self) -> dict[str, Any]:
        return self.manifest["state"]

    @property
    def renderer(self) -> dict[str, str]:
        return self.manifest["renderer"]


def _unreadable(path: Path, scene: str, problem: str) -> GoldenUnreadable:
    error = GoldenUnreadable(f"golden {str(path)!r} of scene {scene!r} {problem}; nothing was compared and nothing "
                            f"was written. If the scene changed on purpose, make its goldens anew: "
                            f"{regen_command(scene, path.parent.parent)}")  # <dir>/<scene>/frame-NNNN.png
    error.problem = f"{path.name} {problem}"  # what regen says it replaced, without the advice to regen
    return error


def _decode_png(path: Path, scene: str) -> np.ndarray:
    from PIL import Image, UnidentifiedImageError

    try:
        data = path.read_bytes()
    except OSError as exc:
        raise _unreadable(path, scene, f"cannot be read ({exc.strerror})") from None
    try:
        with Image.open(io.BytesIO(data)) as picture:
            if picture.format != "PNG":
                raise _unreadable(path, scene, f"is a {picture.format} file, not a PNG")
            picture.load()  # decodes every row: a truncated file fails here, not later
            return np.asarray(picture.convert("RGB"))
    except UnidentifiedImageError:
        raise _unreadable(path, scene, f"is not a PNG (its first bytes are {data[:8]!r})") from None
    except (OSError, SyntaxError, ValueError, zlib.error) as exc:
        raise _unreadable(path, scene, f"is damaged or truncated ({exc})") from None


def _made_for(key: str, made: Any, wanted: Any) -> str:
    """How the golden's ``key`` differs from what the check renders: only the entries that differ."""
    if isinstance(made, dict) and isinstance(wanted, dict):
        differ = sorted(k for k in set(made) | set(wanted) if made.get(k) != wanted.get(k))
        return (f"was made for {key} " + ", ".join(f"{k} {made.get(k)!r}" for k in differ)
                + f", but the check renders {key} " + ", ".join(f"{k} {wanted.get(k)!r}" for k in differ))
    return f"was made for {key} {made!r}, but the check renders {key} {wanted!r}"


def picture_of(directory: Path | str, scene: str, frame: int) -> np.ndarray | None:
    """The stored picture as it is, whatever its manifest says (None when there is none that decodes):
    what regen compares a remade golden with when the old one no longer fits the scene."""
    png, _ = paths(directory, scene, frame)
    try:
        return _decode_png(png, scene) if png.exists() else None
    except GoldenError:
        return None


def read(directory: Path | str, scene: str, frame: int, *, params: dict[str, Any], camera: dict[str, Any],
         size: tuple[int, int]) -> Golden:
    """The golden of ``scene`` at ``frame``, validated against what the check is about to render."""
    png, manifest_path = paths(directory, scene, frame)
    if not png.exists() or not manifest_path.exists():
        missing = [str(p) for p in (png, manifest_path) if not p.exists()]
        raise GoldenMissing(f"no golden for scene {scene!r} at frame {frame}: {' and '.join(missing)} "
                            f"{'does' if len(missing) == 1 else 'do'} not exist. "
                            f"Make it with: {regen_command(scene, directory)} (then look at the picture before you commit it)")
    try:
        manifest = json.loads(manifest_path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise _unreadable(manifest_path, scene, f"has a manifest that is not valid JSON ({exc})") from None
    if not isinstance(manifest, dict) or any(key not in manifest for key in _REQUIRED):
        absent = [k for k in _REQUIRED if not isinstance(manifest, dict) or k not in manifest]
        raise _unreadable(manifest_path, scene, f"has a manifest without {', '.join(absent)}")
    if manifest["format"] != FORMAT:
        raise _unreadable(manifest_path, scene, f"has manifest format {manifest['format']!r}, but this kit reads format {FORMAT}")
    expected = {"scene": scene, "frame": frame, "params": jsonable(params), "camera": jsonable(camera),
                "size": list(size)}
    for key, value in expected.items():
        if manifest[key] != value:
            raise _unreadable(manifest_path, scene, _made_for(key, manifest[key], value))
    image = _decode_png(png, scene)
    if image.shape[:2] != (size[1], size[0]):
        raise _unreadable(png, scene, f"is {image.shape[1]}x{image.shape[0]} pixels, but the scene renders "
                                      f"{size[0]}x{size[1]}")
    return Golden(image=image, manifest=manifest, png=png)


def encode_manifest(manifest: dict[str, Any]) -> bytes:
    """Sorted keys, one line per setting, and one line per body and per target in the state: readable
    in a diff, and small (a state of a hundred bodies is tens of kilobytes)."""
    data = jsonable(manifest)
    state = data.pop("state", None)
    text = json.dumps(data, indent=1, sort_keys=True)
    if state is not None:
        compact = {"separators": (",", ":"), "sort_keys": True}
        parts = []
        for key in sorted(state):
            rows = ",\n  ".join(json.dumps(row, **compact) for row in state[key])
            parts.append(f' "{key}": [\n  {rows}\n ]')
        text = text[:-2] + ',\n "state": {\n' + ",\n".join(parts) + "\n }\n}"
    return (text + "\n").encode("utf-8")


def write(directory: Path | str, scene: str, frame: int, image: np.ndarray, manifest: dict[str, Any]) -> bool:
    """Write a golden and its manifest atomically; return whether any byte changed. Unchanged files
    are not touched. The manifest is written last, so a reader never pairs a new manifest with an
    old picture for longer than the two renames."""
    png, manifest_path = paths(directory, scene, frame)
    changed = False
    for path, data in ((png, encode_png(image)), (manifest_path, encode_manifest(manifest))):
        if path.exists() and path.read_bytes() == data:
            continue
        write_atomically(path, data)
        changed = True
    return changed
