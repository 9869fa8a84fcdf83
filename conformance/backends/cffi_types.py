"""Faster type look-ups in wgpu's cffi bindings, the same types: installed in every process that renders with pygfx.

wgpu-py calls ``ffi.new("WGPUSomething *")`` with type strings, and cffi parses each new string once per
process with pycparser, after a line ``typedef int NAME;`` for every typedef the bindings declare (several
hundred): 73 parses and 1.3 s of CPU in each process that draws a picture with FURY 2, a fifth of an app's
run under the kit (measured on ``examples/pygfx/brick_wall.py``: 1.31 s of 5.62; 0.19 s with this).
Whether a name is a typedef changes how pycparser parses only where the name occurs, so :func:`install`
declares, for a type string, only the typedefs named in it: the same type, parsed from a few lines.

Process-wide (cffi's parser class) and idempotent; without the cffi internals it relies on (another cffi),
it leaves cffi as it is.
"""

from __future__ import annotations

import re

__all__ = ["install"]

_NAME = re.compile(r"[A-Za-z_]\w*")


def install() -> bool:
    """Make cffi parse type strings with only the typedefs they name; whether it is (now) installed."""
    try:
        from cffi import cparser
    except ImportError:
        return False
    parser = getattr(cparser, "Parser", None)
    original = getattr(parser, "parse_type_and_quals", None)
    if original is None:
        return False
    if getattr(original, "_conformance_fast", False):
        return True

    def parse_type_and_quals(self, cdecl):
        declarations = getattr(self, "_declarations", None)
        if not isinstance(declarations, dict):
            return original(self, cdecl)
        named = set(_NAME.findall(cdecl))
        self._declarations = kept = {key: value for key, value in declarations.items()
                                     if not key.startswith("typedef ") or key[8:] in named}
        try:
            return original(self, cdecl)
        finally:
            self._declarations = declarations
            declarations.update(kept)  # whatever the parse declared (an anonymous struct) is kept

    parse_type_and_quals._conformance_fast = True
    parse_type_and_quals.__wrapped__ = original
    parser.parse_type_and_quals = parse_type_and_quals
    return True
