"""Sync implementations shipped with the kit, selectable by the short names of :data:`SHORT_NAMES`.

The names are plain strings, so that validating ``--sync`` imports neither pyBullet nor FURY."""

__all__ = ["SHORT_NAMES"]

#: Implementations shipped with the kit, selectable by these names.
SHORT_NAMES = {
    "reference": "conformance.implementations.reference:ReferenceSync",
    "guide": "conformance.implementations.guide:GuideSync",
    "guide-actor": "conformance.implementations.guide:GuideActorSync",
    "guide-vertex": "conformance.implementations.guide:GuideVertexSync",
    "guide-joint": "conformance.implementations.guide:GuideJointSync",
}
