"""The kit's own imports, read from its source (``ast``, nothing imported): every ``import`` and
``from … import`` of a ``conformance`` module by another, at module level or inside a function, and the
loops they make. ``tests/test_layers.py`` holds the house to its plan with it; run it as a script to see
the loops (``python tests/imports.py``)."""

from __future__ import annotations

import ast
import os
from dataclasses import dataclass
from pathlib import Path

PACKAGE = Path(__file__).resolve().parent.parent / "conformance"


@dataclass(frozen=True)
class Import:
    """``importer`` imports ``imported`` (both dotted module names) at ``line``; ``lazy`` when inside a function."""

    importer: str
    imported: str
    line: int
    lazy: bool

    def __str__(self) -> str:
        return f"{self.importer} -> {self.imported} (line {self.line}{', in a function' if self.lazy else ''})"


def modules(package: Path = PACKAGE) -> dict[str, Path]:
    """Every module of the package by its dotted name (``conformance.apps.judge``); check files included.
    Links (``conformance/scenes`` is one) are followed as Python follows them."""
    found = {}
    for folder, subfolders, names in os.walk(package, followlinks=True):
        subfolders[:] = sorted(d for d in subfolders if d != "__pycache__")
        for file in sorted(n for n in names if n.endswith(".py")):
            parts = (Path(folder) / file).relative_to(package).with_suffix("").parts
            found[".".join((package.name, *parts)).removesuffix(".__init__")] = Path(folder) / file
    return found


def _resolve(name: str, known: dict[str, Path]) -> str | None:
    """The module ``name`` lands in: itself, or the nearest package above it (``x.y.Z`` is a name in ``x.y``)."""
    while name and name not in known:
        name = name.rpartition(".")[0]
    return name or None


def imports(package: Path = PACKAGE) -> list[Import]:
    """Every import of one of the package's modules by another (a module importing itself is left out)."""
    known = modules(package)
    found = []
    for importer, path in known.items():
        tree = ast.parse(path.read_text(encoding="utf-8"), str(path))
        is_package = path.name == "__init__.py"
        lazy_lines = {node.lineno for fn in ast.walk(tree) if isinstance(fn, (ast.FunctionDef, ast.AsyncFunctionDef))
                      for node in ast.walk(fn) if isinstance(node, (ast.Import, ast.ImportFrom))}
        for node in ast.walk(tree):
            targets: list[str] = []
            if isinstance(node, ast.Import):
                targets = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom):
                if node.level:
                    base = importer.split(".")
                    base = base[:len(base) - node.level + (1 if is_package else 0)]
                    stem = ".".join(base + ([node.module] if node.module else []))
                else:
                    stem = node.module or ""
                # ``from x import y`` imports the module x.y when y is one, else a name of x
                targets = [f"{stem}.{alias.name}" if f"{stem}.{alias.name}" in known else stem for alias in node.names]
            for target in targets:
                if not target.startswith(PACKAGE.name):
                    continue
                imported = _resolve(target, known)
                if imported and imported != importer:
                    found.append(Import(importer, imported, node.lineno, node.lineno in lazy_lines))
    return found


def loops(edges: list[Import]) -> list[list[str]]:
    """The import loops: each strongly connected group of two or more modules (Tarjan's algorithm), sorted."""
    graph: dict[str, set[str]] = {}
    for edge in edges:
        graph.setdefault(edge.importer, set()).add(edge.imported)
        graph.setdefault(edge.imported, set())
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    groups: list[list[str]] = []

    def visit(node: str) -> None:  # the graph has ~120 nodes: recursion is fine
        index[node] = low[node] = len(index)
        stack.append(node)
        on_stack.add(node)
        for nxt in sorted(graph[node]):
            if nxt not in index:
                visit(nxt)
                low[node] = min(low[node], low[nxt])
            elif nxt in on_stack:
                low[node] = min(low[node], index[nxt])
        if low[node] == index[node]:
            group = []
            while True:
                member = stack.pop()
                on_stack.discard(member)
                group.append(member)
                if member == node:
                    break
            if len(group) > 1:
                groups.append(sorted(group))

    for node in sorted(graph):
        if node not in index:
            visit(node)
    return sorted(groups)


def ties(group: list[str], edges: list[Import]) -> list[Import]:
    """The imports that hold one loop together."""
    members = set(group)
    return [e for e in edges if e.importer in members and e.imported in members]


if __name__ == "__main__":
    edges = imports()
    found = loops(edges)
    print(f"{len(modules())} modules, {len(edges)} imports between them "
          f"({sum(e.lazy for e in edges)} in functions), {len(found)} loops")
    for group in found:
        print("loop: " + ", ".join(group))
        for edge in ties(group, edges):
            print("    " + str(edge))
