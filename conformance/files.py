"""Writing the kit's files: whole or not at all, and the same bytes for the same content.

Every file the kit writes (goldens and manifests, failure pictures, the HTML report, rendered PNGs)
goes through :func:`write_atomically`: a temporary file in the same directory, flushed to disk, then
renamed over the target, so a reader (or a concurrent pytest-xdist worker) never sees half a file and
a failure leaves the old file whole. :func:`encode_png` makes PNG bytes that depend only on the pixels.
"""

from __future__ import annotations

import io
import os
import tempfile
from pathlib import Path

import numpy as np

__all__ = ["encode_png", "write_atomically"]


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def write_atomically(path: str | os.PathLike, data: bytes) -> Path:
    """Write ``data`` to ``path`` whole or not at all; the file gets the usual permissions."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        os.fchmod(fd, 0o666 & ~_umask())  # mkstemp makes 0600; these are ordinary files to share
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


def encode_png(image: np.ndarray) -> bytes:
    """PNG bytes of an RGB uint8 picture that depend only on its pixels (for a given Pillow and zlib):
    no time, text or physical-size chunks."""
    from PIL import Image

    buffer = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(image, dtype=np.uint8)).save(buffer, format="PNG", optimize=True)
    return buffer.getvalue()
