"""The house's plan, held against the code (issue 31; ``docs/layout.md`` is the map): ``conformance/`` is
in layers, each importing only the layers below it, and no module imports, at module level or inside a
function, a module that imports it back. Python never complains of a loop closed inside a function, so
these tests read the imports from the source (:mod:`imports`)."""

from __future__ import annotations

import textwrap

import pytest

import imports

pytestmark = pytest.mark.fury_free("its verdict cannot depend on the FURY: it reads the kit's sources")

#: The layers, bottom first: what each holds (module names, or a package's prefix ending in ".").
#: A module may import its own layer and those before it.
LAYERS = [
    ("shared leaves", ["conformance.errors", "conformance.files", "conformance.progress", "conformance.validation",
                       "conformance.figures", "conformance.implementations"]),  # implementations' __init__: names only
    ("bullet", ["conformance.bullet."]),
    ("world", ["conformance.world"]),
    ("scenes", ["conformance.scenes."]),
    ("backends", ["conformance.backends."]),
    ("implementations", ["conformance.implementations."]),
    ("judge", ["conformance.judge."]),
    ("sync", ["conformance.sync."]),
    ("rendering", ["conformance.rendering."]),
    ("reports", ["conformance.reports."]),
    ("checks", ["conformance.checks."]),
    ("apps", ["conformance.apps."]),
    ("discrimination", ["conformance.discrimination.", "conformance.zoo."]),
    ("session", ["conformance.session."]),
    ("commands", ["conformance.commands."]),
    ("entry points", ["conformance", "conformance.__main__", "conformance.plugin", "conformance.cli",
                      "conformance.test_"]),
]

#: Imports that run up on purpose, each with its reason.
DELIBERATE = {
    # ``python -m conformance.rendering.measure_*`` are entry points kept where users have run them since
    # they were published (docs/image-tolerances.md, docs/pictures.md): as entry points they may use the
    # scenes' strategies and the commands' argument helpers, as ``cli`` does.
    ("conformance.rendering.measure_silhouettes", "conformance.checks.strategies"),
    ("conformance.rendering.measure_silhouettes", "conformance.commands.common"),
}


def layer_of(module: str) -> int:
    """The index in :data:`LAYERS` of ``module``: the longest name or prefix that holds it."""
    best, length = -1, -1.0
    for index, (_, names) in enumerate(LAYERS):
        for name in names:
            holds = module.startswith(name) if name.endswith((".", "_")) else (module == name or module.startswith(name + "."))
            if name.endswith(".") and module == name[:-1]:
                holds = True  # the package's own __init__
            size = float("inf") if module == name else len(name)  # a module named outright beats any prefix
            if holds and size > length:
                best, length = index, size
    return best


def test_no_import_loops():
    edges = imports.imports()
    found = imports.loops(edges)
    assert not found, "import loops in conformance/ (open each by moving what both sides need below them):\n" + "\n".join(
        "  " + ", ".join(group) + "\n" + "\n".join(f"      {tie}" for tie in imports.ties(group, edges)) for group in found)


def test_every_module_has_a_layer():
    assert [m for m in imports.modules() if layer_of(m) < 0] == []


def upward(edges) -> list:
    """The imports of ``edges`` that go to a higher layer than their importer's, but for :data:`DELIBERATE`."""
    return [e for e in edges if layer_of(e.imported) > layer_of(e.importer) and (e.importer, e.imported) not in DELIBERATE]


def test_an_import_from_a_lower_layer_up_is_seen():
    down = imports.Import("conformance.judge.compare", "conformance.bullet.truth", 1, False)
    up = imports.Import("conformance.bullet.truth", "conformance.judge.compare", 9, True)
    same = imports.Import("conformance.sync.runner", "conformance.sync.protocol", 3, False)
    assert upward([down, up, same]) == [up]


def test_no_import_runs_back_up():
    """Each import goes to the importer's layer or one below it; the deliberate exceptions are listed."""
    upward_ones = upward(imports.imports())
    assert not upward_ones, "imports that run back up a layer (move what is needed below, or the importer up):\n" + "\n".join(
        f"  {e}: {LAYERS[layer_of(e.importer)][0]} -> {LAYERS[layer_of(e.imported)][0]}" for e in upward_ones)


def test_nothing_imports_a_check_file():
    """A check file's helpers that another module needs belong in the toolkit (``checks/``), not in it."""
    assert [str(e) for e in imports.imports() if e.imported.startswith("conformance.test_")] == []


def test_every_deliberate_exception_is_still_needed():
    edges = {(e.importer, e.imported) for e in imports.imports()}
    assert DELIBERATE <= edges, DELIBERATE - edges


@pytest.mark.parametrize("module, layer", [("conformance.bullet.truth", "bullet"), ("conformance.bullet", "bullet"),
                                           ("conformance.implementations", "shared leaves"),
                                           ("conformance.implementations.frames", "implementations"),
                                           ("conformance.test_vertices", "entry points"), ("conformance", "entry points")])
def test_layer_of_picks_the_longest_match(module, layer):
    assert LAYERS[layer_of(module)][0] == layer


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
