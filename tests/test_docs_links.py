"""Every relative link in the README and in docs/ leads somewhere: the file exists and, when the link
names a heading (``page.md#heading``), the page has that heading (GitHub's anchors)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

pytestmark = pytest.mark.fury_free("its verdict cannot depend on the FURY: it reads the docs")

ROOT = Path(__file__).resolve().parent.parent
LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)\)")
FENCE = re.compile(r"^```.*?^```", re.S | re.M)


def anchor(heading: str) -> str:
    """GitHub's anchor for a heading: lower case, punctuation dropped, spaces to hyphens."""
    text = re.sub(r"[^\w\- ]", "", heading.strip().lower())
    return text.replace(" ", "-")


def anchors(page: Path) -> set[str]:
    text = FENCE.sub("", page.read_text(encoding="utf-8"))
    return {anchor(m.group(1)) for m in re.finditer(r"^#{1,6} (.+)$", text, re.M)}


def broken_links(pages) -> list[str]:
    """``page: target (why)`` for every relative link in ``pages`` that leads nowhere."""
    broken = []
    for page in pages:
        text = FENCE.sub("", page.read_text(encoding="utf-8"))
        text = re.sub(r"`[^`\n]*`", "", text)  # code spans are not links
        for target in LINK.findall(text):
            if re.match(r"[a-z]+:", target):
                continue
            path, _, fragment = target.partition("#")
            where = (page.parent / path).resolve() if path else page
            if not where.exists():
                broken.append(f"{page.relative_to(ROOT)}: {target} (no such file)")
            elif fragment and where.suffix == ".md" and fragment not in anchors(where):
                broken.append(f"{page.relative_to(ROOT)}: {target} (no heading #{fragment} in {where.name})")
    return broken


def test_every_link_in_the_readme_and_docs_leads_somewhere():
    pages = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
    assert broken_links(pages) == []


def test_a_link_to_a_missing_page_or_heading_is_found(tmp_path, monkeypatch):
    monkeypatch.setattr(__import__(__name__), "ROOT", tmp_path)
    (tmp_path / "other.md").write_text("# Other page\n\n## A heading (with parts)\n")
    page = tmp_path / "page.md"
    page.write_text("[ok](other.md#a-heading-with-parts) [gone](missing.md) [wrong](other.md#no-such) "
                    "`[code](not-a-link.md)` [web](https://example.org)\n")
    assert broken_links([page]) == ["page.md: missing.md (no such file)",
                                    "page.md: other.md#no-such (no heading #no-such in other.md)"]
