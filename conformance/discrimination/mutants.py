"""Machine-made wrong syncs: mutants of the kit's own right syncs, each judged by the kit (issue 17,
point 2; docs/mutants-vtk.md, docs/discrimination.md#machine-made-mutants).

Every mutant is one small change that mutmut's operators make to a right sync (a number, an operator,
a name, an argument dropped, an assignment turned to ``None``, …), written as an importable module in a
temporary directory of its own and checked like any sync: :func:`conformance.discrimination.verdicts.check` runs the
sync checks on it in a pytest process of its own, Hypothesis profile ``triage``, stopping at the first
failure. What a mutant is, from that run (:func:`classify`):

* **killed**: a check failed on it (``raised`` when the failure is the mutant raising in a step: the kit
  rejects it, but no property had to);
* **crashed** / **timed out**: it killed its worker process, or a call did not return within the limit;
  the kit rejects those too (:mod:`conformance.session.isolation`, :mod:`conformance.sync.time_limit`);
* **not viable**: it cannot be imported, or raises while being set up: it is not a sync at all;
* **survived**: every check passed. A survivor is either *equivalent* (it draws the same thing: the
  argument is kept in :data:`VERDICTS_FILE`, by the mutant's :attr:`Mutant.id`) or a gap in the checks;
* **error**: the run did not complete for another reason (it is reported, never counted).

The score is detected / (mutants − not viable − errors), detected being killed, raised, crashed and
timed out. Before any mutant, the unmutated copy of each target is checked the same way and must pass:
otherwise every mutant would be "killed" by whatever rejects the copy.
"""

from __future__ import annotations

import difflib
import hashlib
import json
import os
import re
import tempfile
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Callable, Sequence

from conformance.errors import ConformanceError

__all__ = ["Mutant", "Result", "SAMPLE", "STATES", "Target", "TARGETS", "VERDICTS_FILE", "classify", "generate", "judge",
           "load_results", "markdown", "read_verdicts", "save_results", "score", "target_names"]

ROOT = Path(__file__).resolve().parents[2]  # the checkout: conformance/discrimination/mutants.py
#: The hand-kept verdicts on survivors: one line each, ``<id> <verdict>: <argument>``.
VERDICTS_FILE = ROOT / "docs" / "mutant-verdicts.txt"
#: Every state a mutant can end in, in the order the tables list them.
STATES = ("killed", "raised", "crashed", "timed out", "survived", "not viable", "error")
DETECTED = ("killed", "raised", "crashed", "timed out")
#: The fast sample CI keeps at 100 % (``--sample``, tests/test_mutants.py), by backend: mutants the full run
#: saw killed by an early check, so each costs one short run.
SAMPLE: dict[str, tuple[str, ...]] = {"vtk": ("7d680577f2", "270130b0a4", "a5a98e7ade", "3af9519bda", "6bf870ac2d",
                                              # the einsum closure: a base read as a link; normals never turned
                                              "7a79b3bcd5", "583b8e6914"),
                                      # FURY 2: the first three of every seventh pygfx reference mutant that were killed
                                      "pygfx": ("441e5dbdbf", "714b72fa2f", "5ccdc76e76")}
#: The module each mutant's sync is loaded from (one temporary directory per mutant, so the name is fixed).
SYNC_MODULE = "mutant_sync"


@dataclass(frozen=True)
class Target:
    """A right sync to mutate: the file whose mutants are made (relative to the repository), the
    functions of it that are mutated (all when empty), and how a mutated file becomes a sync:
    ``modules(mutated_source)`` gives the modules to write (name -> source), one of them
    :data:`SYNC_MODULE`, whose ``factory`` is the sync; ``paths`` are added to the child's import path."""

    name: str
    path: str
    modules: Callable[[str], dict[str, str]]
    factory: str = "ReferenceSync"
    functions: tuple[str, ...] = ()
    paths: tuple[str, ...] = ()


def _backend() -> str:
    from conformance import backends

    return backends.NAME


def _reference_path() -> str:
    return f"conformance/implementations/{_backend()}/reference.py"


def _frames_modules(mutated: str) -> dict[str, str]:
    """frames.py mutated, and the backend's reference importing it instead of the kit's."""
    reference = (ROOT / _reference_path()).read_text(encoding="utf-8")
    rewired = reference.replace("from conformance.implementations.frames import", "from mutant_frames import")
    if rewired == reference:
        raise ConformanceError(f"{_reference_path()} no longer imports conformance.implementations.frames by name; "
                               "conformance/discrimination/mutants.py must rewire the mutated frames.py into it some other way")
    return {"mutant_frames": mutated, SYNC_MODULE: rewired}


def _vectorised_modules(mutated: str) -> dict[str, str]:
    """sync_steps.py mutated, and right_syncs' closure made from it with the backend's arrays."""
    wrapper = ("import importlib\nfrom conformance import backends\nimport mutant_steps\n\n\n"
               "def vectorised_vertex_sync(world):\n"
               "    arrays = importlib.import_module(f'right_syncs_{backends.NAME}')._Arrays\n"
               "    return mutant_steps.vectorised_vertex_sync(world, arrays)\n")
    return {"mutant_steps": mutated, SYNC_MODULE: wrapper}


#: The targets, by name: the file both backends' references share, the backend's own reference, and a
#: right sync in another style (tests/: the closure that rewrites every actor's vertices with einsum,
#: with the one pose helper it calls).
TARGETS = {
    "frames": lambda: Target("frames", "conformance/implementations/frames.py", _frames_modules),
    "reference": lambda: Target("reference", _reference_path(), lambda mutated: {SYNC_MODULE: mutated}),
    "vectorised": lambda: Target("vectorised", "tests/sync_steps.py", _vectorised_modules, "vectorised_vertex_sync",
                                 functions=("vectorised_vertex_sync", "link_frame"), paths=("tests",)),
}


def target_names() -> list[str]:
    return list(TARGETS)


@dataclass(frozen=True)
class Mutant:
    """One change to a target's file: where (function, line), what (the unified diff), and the
    :attr:`id` that names it across runs: a hash of the file, the function, the text changed, what it
    became and which occurrence of that change in the function it is, so it survives edits elsewhere."""

    target: str
    id: str
    function: str
    line: int
    operator: str
    diff: str
    source: str = field(repr=False)


def generate(target: Target) -> list[Mutant]:
    """Every mutant mutmut's operators make of ``target`` inside its functions and methods (mutmut
    leaves module-level code, decorated functions and annotations alone), in the file's order."""
    import libcst as cst
    from libcst.metadata import MetadataWrapper, PositionProvider, WhitespaceInclusivePositionProvider
    from mutmut.mutation.file_mutation import MutationVisitor, deep_replace
    from mutmut.mutation.mutators import mutation_operators
    from mutmut.mutation.pragma_handling import IgnoredCode

    original = (ROOT / target.path).read_text(encoding="utf-8")
    wrapper = MetadataWrapper(cst.parse_module(original))
    visitor = MutationVisitor(mutation_operators, IgnoredCode(set(), set(), set()))
    wrapper.visit(visitor)
    module, positions = wrapper.module, wrapper.resolve(PositionProvider)
    spans = wrapper.resolve(WhitespaceInclusivePositionProvider)
    starts = [0]
    for line in original.splitlines(True):
        starts.append(starts[-1] + len(line))

    def mutated_source(mutation) -> str:
        # The node's text swapped for the mutated node's: 100x cheaper than rendering the whole tree
        # again (deep_replace), which stays the way when the node's text is not exactly its span.
        span = spans[mutation.original_node]
        begin = starts[span.start.line - 1] + span.start.column
        end = starts[span.end.line - 1] + span.end.column
        if original[begin:end] == module.code_for_node(mutation.original_node):
            return original[:begin] + module.code_for_node(mutation.mutated_node) + original[end:]
        return deep_replace(module, mutation.original_node, mutation.mutated_node).code
    names = {}
    for node in module.body:
        if isinstance(node, cst.FunctionDef):
            names[node] = node.name.value
        elif isinstance(node, cst.ClassDef):
            names.update({m: f"{node.name.value}.{m.name.value}" for m in node.body.body if isinstance(m, cst.FunctionDef)})
    mutants, seen = [], {}
    for mutation in visitor.mutations:
        function = names.get(mutation.contained_by_top_level_function)
        if function is None or (target.functions and function.split(".")[0] not in target.functions):
            continue
        source = mutated_source(mutation)
        if source == original:
            continue
        before, after = module.code_for_node(mutation.original_node), module.code_for_node(mutation.mutated_node)
        key = (function, before, after)
        seen[key] = seen.get(key, 0) + 1
        ident = hashlib.sha1("\0".join([target.path, *key, str(seen[key])]).encode()).hexdigest()[:10]
        diff = "".join(line for line in difflib.unified_diff(original.splitlines(True), source.splitlines(True), n=0)
                       if not line.startswith(("---", "+++", "@@")))
        mutants.append(Mutant(target.name, ident, function, positions[mutation.original_node].start.line,
                              type(mutation.original_node).__name__, diff, source))
    return mutants


@dataclass
class Result:
    """What the kit made of one mutant, and what it cost."""

    id: str
    target: str
    state: str
    seconds: float
    check: str = ""
    scene: str = ""
    message: str = ""


def classify(outcome) -> tuple[str, dict]:
    """The state of a mutant from its run (a :class:`conformance.discrimination.verdicts.Outcome` of a stop-at-first run),
    and the record that decided it (``{}`` when none did)."""
    failed = outcome.failed
    if not outcome.records and "did not complete within" in outcome.stderr:
        return "timed out", {}
    if not outcome.records:
        loading = "sync implementation" in outcome.stderr or "SyntaxError" in outcome.stderr or "ImportError" in outcome.stderr
        return ("not viable" if outcome.exitstatus == 4 and loading else "error"), {}
    if not failed:
        return ("survived" if outcome.exitstatus == 0 else "error"), {}
    first = failed[0]
    message = first.get("message", "")
    if "raised while being set up" in message or "returned" in message and "should return a callable" in message:
        return "not viable", first
    if "crashed" in (first.get("kinds") or {}):
        return "crashed", first
    if "did not return within" in message:
        return "timed out", first
    if re.search(r"raised on scene '[^']*' at step", message):
        return "raised", first
    return "killed", first


def judge(target: Target, mutant: Mutant | None, *, pytest_args: Sequence[str] = (), timeout: float | None = None) -> Result:
    """Check one mutant (``None``: the unmutated copy) with the kit, in a pytest process of its own, stopped
    after ``timeout`` seconds (a mutant can loop in the kit's own code, where no per-call limit reaches:
    one ran over 20 minutes in the first full run)."""
    from conformance.discrimination import verdicts

    source = mutant.source if mutant else (ROOT / target.path).read_text(encoding="utf-8")
    with tempfile.TemporaryDirectory(prefix="conformance-mutant-") as tmp:
        for name, text in target.modules(source).items():
            Path(tmp, f"{name}.py").write_text(text, encoding="utf-8")
        env = dict(os.environ)
        env["PYTHONPATH"] = os.pathsep.join([tmp, *(str(ROOT / p) for p in target.paths), str(ROOT),
                                             *filter(None, [env.get("PYTHONPATH")])])
        started = time.monotonic()
        outcome = verdicts.check(f"{SYNC_MODULE}:{target.factory}", stop_at_first=True, pytest_args=pytest_args, env=env,
                                  timeout=timeout)
        seconds = time.monotonic() - started
    state, record = classify(outcome)
    message = record.get("message", "") or (outcome.stderr.strip().splitlines() or [""])[-1]
    return Result(mutant.id if mutant else "unmutated", target.name, state, round(seconds, 1), record.get("check", ""),
                  str(record.get("scene") or ""), message.splitlines()[0][:300] if message else "")


# -- results kept between runs, verdicts, the score and the page -------------------------------------

def load_results(path: str | os.PathLike) -> dict[str, Result]:
    """Results kept by :func:`save_results`, by mutant id ({} when there is no such file)."""
    try:
        payload = json.loads(Path(path).read_text(encoding="utf-8"))
    except FileNotFoundError:
        return {}
    except (OSError, ValueError) as exc:
        raise ConformanceError(f"--results {path}: not a file of mutant results ({exc}); remove it to start afresh") from None
    return {r["id"]: Result(**r) for r in payload["results"]}


def save_results(path: str | os.PathLike, results: dict[str, Result], meta: dict) -> None:
    from conformance.files import write_atomically

    payload = {**meta, "results": [asdict(r) for r in results.values()]}
    write_atomically(path, json.dumps(payload, indent=1).encode("utf-8"))


def read_verdicts(path: str | os.PathLike = VERDICTS_FILE) -> dict[str, str]:
    """The hand-kept verdicts, by mutant id: ``<id> <verdict>: <argument>`` a line, ``#`` comments."""
    verdicts = {}
    try:
        lines = Path(path).read_text(encoding="utf-8").splitlines()
    except FileNotFoundError:
        return {}
    for number, line in enumerate(lines, 1):
        if not line.strip() or line.startswith("#"):
            continue
        ident, _, verdict = line.partition(" ")
        if not re.fullmatch(r"[0-9a-f]{10}", ident) or not verdict.strip():
            raise ConformanceError(f"{path}:{number}: should be '<10-hex-digit mutant id> <verdict>: <argument>', not {line!r}")
        verdicts[ident] = verdict.strip()
    return verdicts


def score(results: Sequence[Result]) -> tuple[int, int]:
    """``(detected, viable)``: the mutants the kit rejects, out of those that are syncs at all."""
    viable = [r for r in results if r.state not in ("not viable", "error")]
    return sum(r.state in DETECTED for r in viable), len(viable)


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", "<br>")


def _change(diff: str) -> str:
    return "<br>".join(f"`{line.rstrip()}`" for line in diff.splitlines()).replace("|", "\\|")


def markdown(mutants: dict[str, list[Mutant]], results: dict[str, Result], verdicts: dict[str, str], *, title: str,
             made_by: str, sample: Sequence[str] = ()) -> str:
    """The page: the score per target, the cost, which checks killed them, then every survivor with its
    diff and verdict (from :data:`VERDICTS_FILE`; "**no verdict**" when none is written), then the
    mutants that are not syncs at all and any run that did not complete."""
    lines = [f"# {title}", "", f"<!-- generated by `{made_by}`; do not edit -->", "", f"Made by `{made_by}` (see [discrimination.md](discrimination.md#machine-made-mutants)).", "",
             "| target | file | mutants | judged | " + " | ".join(STATES) + " | score |", "|---|---|" + "---|" * (len(STATES) + 3)]
    every = []
    for name, found in mutants.items():
        judged = [results[m.id] for m in found if m.id in results]
        every += judged
        detected, viable = score(judged)
        counts = [sum(r.state == s for r in judged) for s in STATES]
        path = TARGETS[name]().path
        lines.append(f"| {name} | `{path}` | {len(found)} | {len(judged)} | " + " | ".join(map(str, counts))
                     + f" | {detected}/{viable}" + (f" = {100 * detected / viable:.1f} %" if viable else "") + " |")
    detected, viable = score(every)
    lines += ["", f"**Mutation score: {detected}/{viable}" + (f" = {100 * detected / viable:.1f} %" if viable else "")
              + "** of the viable mutants judged (killed, raised, crashed or timed out, out of all but the not viable); "
              + f"{sum(r.state == 'survived' and verdicts.get(r.id, '').startswith('equivalent') for r in every)} of the "
              + f"{sum(r.state == 'survived' for r in every)} survivors are argued equivalent below."]
    for state in ("killed", "survived"):
        times = sorted(r.seconds for r in every if r.state == state)
        if times:
            lines.append(f"- {state}: {len(times)} mutants, median {times[len(times) // 2]:.0f} s each "
                         f"(min {times[0]:.0f} s, max {times[-1]:.0f} s)")
    lines.append(f"- all judged: {sum(r.seconds for r in every) / 60:.0f} min of runs, one at a time")
    if sample:
        lines.append(f"- the fast sample (`--sample`, `tests/test_mutants.py`): {', '.join(f'`{s}`' for s in sample)}")
    killers: dict[str, int] = {}
    for r in every:
        if r.state == "killed":
            killers[r.check] = killers.get(r.check, 0) + 1
    lines += ["", "Which check killed them first (checks run cheapest first, so this says which is quickest, not "
              "which is the only one):", "", "| check | mutants |", "|---|---|"]
    lines += [f"| `{c}` | {n} |" for c, n in sorted(killers.items(), key=lambda kv: -kv[1])]
    by_id = {m.id: m for found in mutants.values() for m in found}
    survivors = [r for r in every if r.state == "survived"]
    lines += ["", f"## Survivors ({len(survivors)})", "",
              "Each with its verdict: *equivalent* (it draws the same thing, and why) or a *gap* in the checks. "
              "The verdicts are kept in `docs/mutant-verdicts.txt` by id.", "",
              "| id | target | where | change | verdict |", "|---|---|---|---|---|"]
    for r in survivors:
        m = by_id[r.id]
        lines.append(f"| `{m.id}` | {m.target} | `{m.function}` line {m.line} | {_change(m.diff)} | "
                     f"{_cell(verdicts.get(m.id, '**no verdict**'))} |")
    others = [r for r in every if r.state in ("not viable", "error")]
    lines += ["", f"## Not viable, and runs that did not complete ({len(others)})", "",
              "Not counted in the score: a mutant that cannot be imported or raises while being set up is not a sync.", "",
              "| id | target | where | change | state | why |", "|---|---|---|---|---|---|"]
    for r in others:
        m = by_id[r.id]
        lines.append(f"| `{m.id}` | {m.target} | `{m.function}` line {m.line} | {_change(m.diff)} | {r.state} | {_cell(r.message[:160])} |")
    return "\n".join(lines) + "\n"
