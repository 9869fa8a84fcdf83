"""Sync implementations shipped with the kit (selectable by the short names in ``conformance.sync``)."""
