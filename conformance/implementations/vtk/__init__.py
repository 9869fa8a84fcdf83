"""The kit's sync implementations written against FURY 0.12 (VTK actors)."""
