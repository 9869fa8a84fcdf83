"""Drawn against expected, with no pytest: ``compare`` (a drawing's vertices, normals and bounds against
pyBullet's poses, as result records), ``tolerances`` (how far is still right) and ``diagnosis`` (which
known mistake a wrong drawing is). Imports ``bullet``, ``backends`` and the shared leaves (internal)."""
