"""The kit's one exception tree.

Every error the kit raises on purpose derives from :class:`ConformanceError`, so a caller can catch
the kit's complaints without catching its own bugs. Messages are one paragraph: what was wrong, the
value that was wrong, and what to do about it.
"""

from __future__ import annotations

__all__ = [
    "BackendError",
    "BadArgument",
    "ConformanceError",
    "DisplayUnavailable",
    "GoldenError",
    "GoldenFramesBadly",
    "GoldenMissing",
    "GoldenUnreadable",
    "ImageSizeMismatch",
    "InvalidArgument",
    "SceneError",
    "SyncCrashed",
    "SyncError",
    "SyncLoadError",
    "SyncProtocolError",
    "SyncRaised",
    "SyncTimedOut",
]


class ConformanceError(Exception):
    """Base of every error the kit raises deliberately."""


class InvalidArgument(ConformanceError, ValueError):
    """A parameter given to the kit (a scene size, a step count, an option) is out of range."""


class BadArgument(InvalidArgument):
    """An option, ini value, environment variable or command-line argument was refused (see
    :mod:`conformance.validation`); the message names it, its value and type, and what it should be.
    The pytest plugin turns it into a usage error, the command line into ``error:`` and exit status 2."""


class SceneError(ConformanceError):
    """A reference scene cannot be built or described as asked."""


class BackendError(ConformanceError):
    """No backend for the installed FURY (none installed, or a version the kit has no backend for),
    or the backend's renderer cannot start (no Vulkan adapter for FURY 2)."""


class DisplayUnavailable(ConformanceError):
    """No X display is set and none could be started for off-screen rendering, the X server refuses
    connections, or VTK's OpenGL driver cannot start on it (:mod:`conformance.backends.renderer_start`)."""


class SyncError(ConformanceError):
    """A sync implementation under test could not be used; the message names it."""


class SyncLoadError(SyncError):
    """The ``--sync`` spec does not name an importable object."""


class SyncProtocolError(SyncError):
    """The named object does not follow the sync protocol (see :mod:`conformance.sync`)."""


class SyncRaised(SyncError):
    """The sync implementation raised while the kit was running it."""


class SyncTimedOut(SyncError):
    """A call into the sync implementation did not return within the time limit
    (:mod:`conformance.sync.time_limit`)."""


class SyncCrashed(SyncError):
    """The sync implementation crashed the process (a signal, ``os._exit``) on this scene earlier in the
    run, so a check that would run it there again fails at once (:mod:`conformance.session.isolation`)."""


class GoldenError(ConformanceError):
    """A golden snapshot or its manifest cannot be used as it is; the message names the file and the
    command that makes it anew. Nothing is written when this is raised."""


class GoldenMissing(GoldenError):
    """No golden (or no manifest beside it) exists for a scene's frame."""


class GoldenUnreadable(GoldenError):
    """A golden is not a PNG, is truncated, has the wrong size, or its manifest is malformed or was
    made for other scene parameters, another frame, or another camera."""


class GoldenFramesBadly(GoldenError):
    """``regen`` was asked for goldens of a scene whose camera cuts a body off, or shows one as a dot:
    such a picture passes whatever the sync does to that body, so none is made."""


class ImageSizeMismatch(GoldenError):
    """A render and its golden differ in size: re-record the golden rather than compare pixels."""
