"""The README and docs/*.md link committed files (figures, tables, examples): every relative
link must resolve, so a renamed output or a forgotten `git add` shows up here."""

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
LINK = re.compile(r"\]\(([^)\s]+)\)")


def _relative_links(md: Path):
    for target in LINK.findall(md.read_text()):
        if re.match(r"[a-z]+:", target) or target.startswith("#"):
            continue  # URL or in-page anchor
        yield target.split("#", 1)[0]


@pytest.mark.parametrize("md", DOCS, ids=lambda p: str(p.relative_to(ROOT)))
def test_relative_links_resolve(md):
    missing = [t for t in _relative_links(md) if not (md.parent / t).exists()]
    assert not missing, f"{md.relative_to(ROOT)} links missing files: {missing}"


def test_readme_links_the_paper_and_work_precision_write_ups():
    links = set(_relative_links(ROOT / "README.md"))
    assert {"docs/paper.md", "docs/work-precision.md"} <= links
