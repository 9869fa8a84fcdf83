"""The house's plan, held against the code: no module of ``conformance`` imports, at module level or
inside a function, a module that imports it back (issue 31; ``docs/layout.md``). Python never complains
of a loop closed inside a function, so this test reads the imports from the source (:mod:`imports`)."""

from __future__ import annotations

import textwrap

import imports


def test_no_import_loops():
    edges = imports.imports()
    found = imports.loops(edges)
    assert not found, "import loops in conformance/ (open each by moving what both sides need below them):\n" + "\n".join(
        "  " + ", ".join(group) + "\n" + "\n".join(f"      {tie}" for tie in imports.ties(group, edges)) for group in found)


def test_the_reader_sees_a_loop_closed_inside_a_function_and_every_form_of_import(tmp_path):
    """The reader must see what the loop test looks for: a loop whose one side imports inside a function,
    ``import a.b``, ``from a import b`` (a module), ``from a.b import name``, relative imports, and the
    package's ``__init__``."""
    package = tmp_path / "conformance"
    (package / "inner").mkdir(parents=True)
    files = {
        "__init__.py": "from conformance.top import VALUE\n",
        "top.py": "import conformance.inner.low\nVALUE = 1\n",
        "inner/__init__.py": "",
        "inner/low.py": "from . import other\n",
        "inner/other.py": "def late():\n    from conformance.top import VALUE\n    return VALUE\n",
        "alone.py": "from conformance import top\n",
    }
    for name, text in files.items():
        (package / name).write_text(textwrap.dedent(text))
    edges = imports.imports(package)
    pairs = {(e.importer, e.imported, e.lazy) for e in edges}
    assert ("conformance", "conformance.top", False) in pairs
    assert ("conformance.top", "conformance.inner.low", False) in pairs
    assert ("conformance.inner.low", "conformance.inner.other", False) in pairs
    assert ("conformance.inner.other", "conformance.top", True) in pairs
    assert ("conformance.alone", "conformance.top", False) in pairs
    assert imports.loops(edges) == [["conformance.inner.low", "conformance.inner.other", "conformance.top"]]
