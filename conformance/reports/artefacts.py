"""Image-check artefacts on disk: each check's pictures as PNGs, and every record as a JSON line.

Layout of a results directory (paths in ``ImageCheck.images`` are relative to it)::

    records-<worker>.jsonl                              one record a line, one file per process
    <kind>/<scene>/frame<N>[-<hash>]-<role>.png         the pictures of one check

``<worker>`` is pytest-xdist's worker id (``$PYTEST_XDIST_WORKER``: ``gw0``, ``gw1`` …) or ``main``,
so no two processes ever write the same records file. ``<hash>`` is a short hash of the record's
``params`` and ``sync``, present when either is set, so a property-based check's examples and two
syncs checked into one directory do not overwrite each other's pictures.

Guarantees: every PNG appears under its final name complete or not at all (written to a temporary
file in the same directory, then renamed), and carries no timestamp or other metadata, so identical
pictures give byte-identical files. A records line is appended in one ``write``; a process killed
mid-line leaves at most one corrupt last line, which :func:`read_records` skips with a warning.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import shutil
import warnings
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from conformance.errors import InvalidArgument
from conformance.files import encode_png, write_atomically
from conformance.rendering.records import KINDS, ImageCheck

__all__ = [
    "CorruptRecordWarning",
    "ROLES",
    "append_record",
    "artefact_path",
    "clear",
    "read_records",
    "worker_id",
    "write_artefacts",
    "write_png",
]

#: The picture roles each kind of check may write, in the order a report shows them.
ROLES: dict[str, tuple[str, ...]] = {
    # The golden, the live reference (reference sync, this renderer), the sync's render; the sync verdict's
    # difference (render vs live reference) and the renderer verdict's (live reference vs golden).
    "golden": ("expected", "reference", "actual", "difference", "reference_difference"),
    "silhouette": ("pybullet_mask", "fury_mask", "mask_difference"),
    "framing": ("actual",),
    "vertices": ("outlined",),
}

_RECORDS_GLOB = "records-*.jsonl"
# Scene names and worker ids become path components: keep them to a portable, harmless alphabet.
_UNSAFE = re.compile(r"[^A-Za-z0-9_.-]+")


class CorruptRecordWarning(UserWarning):
    """A line of a records file could not be read as an :class:`ImageCheck`; it was skipped."""


def worker_id() -> str:
    """This process's name in records file names: the pytest-xdist worker id, else ``main``."""
    return _safe(os.environ.get("PYTEST_XDIST_WORKER", "") or "main")


def _safe(name: str) -> str:
    cleaned = _UNSAFE.sub("_", name).strip(".")
    return cleaned or "_"


def _variant(record: ImageCheck) -> str:
    """Short, stable hash of what distinguishes two checks of the same scene and frame."""
    if not record.params and not record.sync:
        return ""
    text = json.dumps({"params": record.params, "sync": record.sync}, sort_keys=True, default=_jsonable)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()[:10]


def artefact_path(record: ImageCheck, role: str) -> Path:
    """Where the ``role`` picture of ``record`` goes, relative to the results directory."""
    allowed = ROLES.get(record.kind, ())
    if role not in allowed:
        raise InvalidArgument(f"picture role {role!r} for a {record.kind} check, but should be one of {allowed}")
    variant = _variant(record)
    stem = f"frame{int(record.frame)}" + (f"-{variant}" if variant else "")
    return Path(record.kind, _safe(record.scene), f"{stem}-{role}.png")


def write_png(path: str | os.PathLike, picture: np.ndarray) -> Path:
    """Write an RGB (or grey, or boolean mask) picture as a PNG, atomically and without metadata.

    The same array always gives the same bytes (for a given Pillow and zlib): no tIME, tEXt or pHYs
    chunk is written and the compression level is fixed.
    """
    path = Path(path)
    # Several workers may write the same picture: the last complete one wins.
    return write_atomically(path, encode_png(_as_rgb(picture, what=path.name)))


def _as_rgb(picture: np.ndarray, *, what: str) -> np.ndarray:
    array = np.asarray(picture)
    if array.dtype == bool:
        array = array.astype(np.uint8) * 255
    if array.ndim == 2:
        array = np.repeat(array[:, :, None], 3, axis=2)
    if array.ndim != 3 or array.shape[2] != 3 or array.dtype != np.uint8 or 0 in array.shape:
        raise InvalidArgument(f"picture {what!r} is {array.dtype} of shape {array.shape}, but should be "
                              "uint8 of shape (height, width, 3) (or a 2-D grey or boolean mask)")
    return np.ascontiguousarray(array)


def _remove(path: str | os.PathLike) -> None:
    try:
        os.unlink(path)
    except FileNotFoundError:
        pass


def write_artefacts(record: ImageCheck, results_dir: str | os.PathLike,
                    pictures: Mapping[str, np.ndarray] | None = None) -> ImageCheck:
    """Write every picture given for ``record`` and append the record to this process's records file.

    What a check keeps is the caller's choice (the plugin gives a failure all its pictures, a pass
    none unless ``--conformance-keep-passing`` asks): every record is appended, pictures or not, so the report
    shows every image check of the run. ``record.images`` is updated in place with the paths written
    (relative to ``results_dir``), and the record returned.
    """
    results_dir = Path(results_dir)
    for role, picture in (pictures or {}).items():
        relative = artefact_path(record, role)
        write_png(results_dir / relative, picture)
        record.images[role] = relative.as_posix()
    append_record(record, results_dir)
    return record


def append_record(record: ImageCheck, results_dir: str | os.PathLike) -> Path:
    """Append ``record`` as one JSON line to ``results_dir/records-<worker>.jsonl``."""
    results_dir = Path(results_dir)
    results_dir.mkdir(parents=True, exist_ok=True)
    # Insertion order kept (no sort_keys): per-target rows read best in the order the check wrote them.
    line = json.dumps(record.to_json(), default=_jsonable, ensure_ascii=False) + "\n"
    path = results_dir / f"records-{worker_id()}.jsonl"
    # One write of one line to a file only this process writes: whole lines, never interleaved.
    with open(path, "a", encoding="utf-8") as fh:
        fh.write(line)
    return path


def _jsonable(value: Any) -> Any:
    """numpy scalars and arrays, paths and sets as plain JSON values (metrics are often numpy floats)."""
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    if isinstance(value, (set, frozenset)):
        return sorted(value, key=repr)
    raise TypeError(f"{type(value).__name__} is not JSON serialisable")


def read_records(results_dir: str | os.PathLike) -> list[ImageCheck]:
    """Every record in ``results_dir``'s records files, file by file (sorted by name), line by line.

    A line that is not a valid record is skipped with a :class:`CorruptRecordWarning` naming the
    file and line: one bad line must not hide the rest of a run. A missing directory gives ``[]``.
    """
    results_dir = Path(results_dir)
    if not results_dir.is_dir():
        return []
    records = []
    for path in sorted(results_dir.glob(_RECORDS_GLOB)):
        with open(path, encoding="utf-8", errors="replace") as fh:
            for number, line in enumerate(fh, start=1):
                if not line.strip():
                    continue
                try:
                    data = json.loads(line)
                    if not isinstance(data, dict):
                        raise TypeError(f"a JSON {type(data).__name__}, not an object")
                    records.append(ImageCheck.from_json(data))
                except (ValueError, TypeError) as err:
                    warnings.warn(f"{path}:{number}: skipped a corrupt image-check record ({err})",
                                  CorruptRecordWarning, stacklevel=2)
    return records


def clear(results_dir: str | os.PathLike) -> None:
    """Remove a previous run's records files and pictures from ``results_dir`` (nothing else).

    Call it once per run before any check writes (with pytest-xdist: in the controller, before the
    workers start), since records files are appended to.
    """
    results_dir = Path(results_dir)
    for path in results_dir.glob(_RECORDS_GLOB):
        _remove(path)
    for kind in KINDS:
        shutil.rmtree(results_dir / kind, ignore_errors=True)
