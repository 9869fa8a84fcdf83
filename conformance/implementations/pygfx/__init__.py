"""The kit's sync implementations written against FURY 2 (pygfx actors)."""
