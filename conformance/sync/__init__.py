"""The user's code, loaded and called: the sync protocol and its loading (``protocol``, whose names are
re-exported here), the journal of where a call into it is (``journal``, for crash isolation), the time
limit on each call (``time_limit``), running a scene frame by frame (``runner``), the user's own scenes
(``own_scenes``) and the commands printed to run it again (``printed``). Imports ``judge``,
``implementations``, ``backends``, ``scenes``, ``bullet``, ``world`` and the shared leaves.

Public: ``load``, ``SyncImplementation``, ``Syncer``, ``SHORT_NAMES`` and ``ENV_VAR`` (README, "The sync
protocol"); the modules are internal."""

from conformance.sync.protocol import ENV_VAR, SHORT_NAMES, Syncer, SyncImplementation, load

__all__ = ["ENV_VAR", "SHORT_NAMES", "SyncImplementation", "Syncer", "load"]
