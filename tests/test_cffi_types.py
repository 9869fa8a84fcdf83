"""``conformance.backends.cffi_types``: wgpu's type strings parse to the same cffi types, from a few lines.

FURY 2 only (wgpu's bindings are there): the speed-up is installed in every process that renders with pygfx
(the kit's and an app's under the kit), so a type it parsed differently would be a wrong struct handed to
wgpu. Each type string is parsed twice by wgpu's own parser, as cffi does and as the kit does, and the two
must name the same C type with the same qualifiers.
"""

from __future__ import annotations

import re

import pytest

from conformance import backends
from conformance.backends import cffi_types

pytestmark = pytest.mark.skipif(backends.NAME != "pygfx", reason="wgpu's cffi bindings are FURY 2's; FURY 0.12 has none")


def _parser():
    from wgpu.backends.wgpu_native._ffi import ffi

    return ffi._parser


def _type_strings(parser) -> list[str]:
    """Every 12th typedef of wgpu's bindings, as wgpu-py names them (``T *``), and a few other forms."""
    names = sorted(key[8:] for key in parser._declarations if key.startswith("typedef "))
    return [f"{name} *" for name in names[::12]] + [f"{names[0]}[4]", f"const {names[1]} *", "uint32_t *", "char *"]


def _differences(parser, strings) -> list[str]:
    """The strings the installed speed-up parses to another type than cffi's own parse does."""
    fast = type(parser).parse_type_and_quals
    slow = getattr(fast, "__wrapped__", None)
    assert slow is not None, "cffi_types.install() should keep cffi's own parse as __wrapped__"
    found = []
    for text in strings:
        try:
            got = fast(parser, text)
        except Exception as exc:  # a parse error is a difference
            got = exc
        expected = slow(parser, text)
        if isinstance(got, Exception) or (got[0]._get_c_name(), got[1]) != (expected[0]._get_c_name(), expected[1]):
            found.append(f"{text!r}: {got!r}, but should be {expected!r}")
    return found


def test_wgpus_type_strings_parse_to_the_same_types():
    assert cffi_types.install()
    parser = _parser()
    strings = _type_strings(parser)
    assert len(strings) > 30 and not _differences(parser, strings)


def test_a_speed_up_that_left_out_the_named_typedefs_would_be_seen(monkeypatch):
    assert cffi_types.install()
    monkeypatch.setattr(cffi_types, "_NAME", re.compile(r"(?!)"))  # names nothing: no typedef is declared
    parser = _parser()
    assert _differences(parser, _type_strings(parser)[:5])
