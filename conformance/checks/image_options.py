"""The image checks' options, and what the checks need from them.

Each option has an ini twin (command line first): ``--conformance-golden-dir``, ``--conformance-image-tolerance``,
``--conformance-results``, ``--conformance-keep-passing``, and ``--regen-golden``. :func:`from_config`
reads them once per session. It is also where the whole plugin's options are checked, once, when
pytest is configured: the rules live in :mod:`conformance.validation`, and a refused value becomes a
``pytest.UsageError`` naming the option, the value and what it should be.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pytest

from conformance.validation import DEFAULT_RESULTS

__all__ = ["Pictures", "add_options", "from_config", "golden_verdicts_summary"]

_KEY = pytest.StashKey["Pictures"]()
_REGENERATED = "conformance_golden_regenerated"


def add_options(group, parser) -> None:
    group.addoption("--conformance-golden-dir", dest="conformance_golden_dir", metavar="DIR", default=None,
                    help="directory of golden snapshots (default: the kit's own)")
    parser.addini("conformance_golden_dir", "default for --conformance-golden-dir", default=None)
    group.addoption("--conformance-image-tolerance", dest="conformance_image_tolerance", metavar="SET", default=None,
                    help="image tolerance set: auto (the sync's render against a live reference render: same-renderer; "
                    "the live reference against the golden: same-renderer when the golden's manifest names this machine's "
                    "renderer or the pictures agree within it, else other-renderer), same-renderer or other-renderer "
                    "(then both verdicts use it). Default auto")
    parser.addini("conformance_image_tolerance", "default for --conformance-image-tolerance", default=None)
    group.addoption("--conformance-results", dest="conformance_results", metavar="DIR", default=None,
                    help=f"where failure pictures, image-check records and report.html go (default {DEFAULT_RESULTS})")
    parser.addini("conformance_results", "default for --conformance-results", default=None)
    group.addoption("--conformance-keep-passing", dest="conformance_keep_passing", action="store_true", default=None,
                    help="keep the pictures of passing image checks too (the report then shows them)")
    parser.addini("conformance_keep_passing", "default for --conformance-keep-passing", type="bool", default=False)
    group.addoption("--regen-golden", dest="conformance_regen_golden", action="store_true", default=False,
                    help="make the goldens of the selected scenes anew (reference sync) before checking them; "
                    "prints what changed. Goldens are never written without this")


@dataclass
class Pictures:
    """What the image checks need from the session: where goldens are, which tolerance set, where
    to put pictures, whether to regenerate."""

    golden_dir: Path | None  # None: each scene's own (conformance.sync.own_scenes.golden_dir)
    tolerance: str  # one of conformance.validation.IMAGE_TOLERANCE_CHOICES
    results: Path
    keep_passing: bool
    regen: bool
    _renderer: dict[str, str] | None = field(default=None, repr=False)

    # -- the checks' side ---------------------------------------------------------------------
    def golden_dir_for(self, scene: str) -> Path:
        """Where ``scene``'s goldens are read and regenerated: the directory given, else the scene's own
        (the kit's for its scenes, ``golden/<backend>/`` beside your file for yours)."""
        from conformance.sync import own_scenes

        return self.golden_dir if self.golden_dir is not None else own_scenes.golden_dir(scene)

    @property
    def renderer(self) -> dict[str, str]:
        if self._renderer is None:
            from conformance import backends

            self._renderer = backends.renderer_info()
        return self._renderer

    @property
    def override(self) -> str | None:
        """The tolerance set asked for, or None for the automatic choice (:mod:`conformance.rendering.reftest`)."""
        return None if self.tolerance == "auto" else self.tolerance

    def keep(self, record, images: dict[str, Any]) -> None:
        """Write a check's pictures (failures always; passes when asked) and its record."""
        from conformance.reports import artefacts

        record.details.setdefault("renderer", self.renderer)
        artefacts.write_artefacts(record, self.results, images if (not record.passed or self.keep_passing) else {})

    def note_regenerated(self, node, changes) -> None:
        for change in changes:
            node.user_properties.append((_REGENERATED, change.describe()))

    # -- the session's side -------------------------------------------------------------------
    def describe(self) -> str:
        where = ("each scene's own (the kit's; yours in golden/<backend>/ beside your scene file)" if self.golden_dir is None
                 else str(self.golden_dir))
        tolerance = ("auto (the sync against a live reference render: same-renderer; the live reference against "
                     "the golden: same-renderer for goldens this machine's renderer made or that it equals, else other-renderer)"
                     if self.tolerance == "auto" else self.tolerance)
        return (f"goldens: {where}; image tolerance {tolerance}; results in {self.results}"
                + ("; REGENERATING goldens" if self.regen else ""))

    def start_session(self) -> None:
        """Forget the pictures and records of an earlier run (only what the kit writes there), so
        the report shows this run alone. Called once, by the controller, before any check runs."""
        from conformance.reports import artefacts

        artefacts.clear(self.results)
        (self.results / "report.html").unlink(missing_ok=True)

    def write_report(self, sync: str):
        from conformance.reports import artefacts, report

        if not self.results.is_dir():
            return None
        records = artefacts.read_records(self.results)
        if not records:
            return None
        from conformance.rendering import golden

        versions = ", ".join(f"{name} {version}" for name, version in golden.library_versions().items())
        from conformance import backends

        renderers = sorted({backends.renderer_label(r["details"]["renderer"])
                            for r in (record.to_json() for record in records) if "renderer" in r["details"]})
        self.golden_summary = golden_verdicts_summary(records)
        header = [f"sync under test: {sync}", backends.describe(), f"versions: {versions}",
                  *(f"renderer: {r}" for r in renderers), self.describe(),
                  *([self.golden_summary] if self.golden_summary else [])]
        self.report_path = report.write_report(records, self.results, title="FURY–pyBullet conformance: checks with pictures",
                                               header_lines=header)
        return self.report_path

    def summarize(self, terminalreporter) -> None:
        regenerated = [value for report in terminalreporter.stats.get("passed", []) + terminalreporter.stats.get("failed", [])
                       for key, value in getattr(report, "user_properties", ()) if key == _REGENERATED]
        if regenerated:
            terminalreporter.section("goldens regenerated")
            for line in regenerated:
                terminalreporter.write_line(line)
        if getattr(self, "golden_summary", ""):
            terminalreporter.write_line(f"conformance: {self.golden_summary}")
        path = getattr(self, "report_path", None)
        if path is not None:
            terminalreporter.write_line(f"conformance: report (image checks, failing vertex checks): {path}")


def golden_verdicts_summary(records) -> str:
    """One line over every golden frame judged in the run: how many failed the sync verdict, how many
    the renderer verdict, and the sets the renderer verdict used ('' when no golden was judged)."""
    verdicts = [r.details["verdicts"] for r in records if r.kind == "golden" and isinstance(r.details.get("verdicts"), dict)]
    if not verdicts:
        return ""
    failed = {name: sum(not v[name]["passed"] for v in verdicts) for name in ("sync", "renderer")}
    sets: dict[str, int] = {}
    for v in verdicts:
        sets[v["renderer"]["tolerance_set"]] = sets.get(v["renderer"]["tolerance_set"], 0) + 1
    return (f"golden pictures: {len(verdicts)} frames; sync verdict (against a live reference render) "
            f"{failed['sync']} failed; renderer verdict (live reference against the golden) {failed['renderer']} "
            f"failed, judged with " + ", ".join(f"{name} {n}" for name, n in sorted(sets.items())))


def from_config(config) -> Pictures:
    """The session's :class:`Pictures`, read and validated once (with every other option of the plugin)."""
    cached = config.stash.get(_KEY, None)
    if cached is not None:
        return cached
    from conformance import validation
    from conformance.errors import BadArgument

    try:
        options = validation.plugin_options(config)
    except BadArgument as err:
        raise pytest.UsageError(str(err)) from None
    golden_dir = options.golden_dir.resolve() if options.golden_dir is not None else None
    pictures = Pictures(golden_dir=golden_dir, tolerance=options.image_tolerance, results=options.results.resolve(),
                        keep_passing=options.keep_passing, regen=options.regen)
    config.stash[_KEY] = pictures
    return pictures
