"""The documentation site's code runs (docs/site/: getting started, tutorials, how-to guides).

Every page's ```python blocks run in order as one script in a temporary directory, with the
runner the site's build uses (docs/site/_ext/tutorials.py), so what the site shows is what
runs here; the pages check their own results (closed forms, references, other models) with
asserts, and every figure a page shows must be written by its code. About 30 s in all on the
2-core development machine (the Dask sweep, cluster start included, is almost half of it).
"""

import importlib.util
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SITE = ROOT / "docs" / "site"
_spec = importlib.util.spec_from_file_location("_site_runner", SITE / "_ext" / "tutorials.py")
runner = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(runner)

PAGES = runner.pages()
TUTORIALS = ["four-bar", "slider-crank", "beam-models", "fe-body", "sweep", "events", "spatial"]


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(SITE)))
def test_page_code_runs_and_writes_the_figures_it_shows(page, tmp_path):
    runner.run(page, tmp_path)
    missing = [f for f in runner.figures(page) if not (tmp_path / f).is_file()]
    assert not missing, f"{page.relative_to(SITE)} shows figures its code does not write: {missing}"


def test_every_tutorial_in_the_index_has_code_and_a_figure():
    index = (SITE / "tutorials" / "index.md").read_text()
    listed = re.findall(r"\]\(([\w-]+)\.md\)", index)
    assert listed == TUTORIALS
    for name in TUTORIALS:
        page = SITE / "tutorials" / f"{name}.md"
        assert page in PAGES and runner.figures(page), name


def test_runner_reports_the_failing_page_and_line(tmp_path):
    page = tmp_path / "broken.md"
    page.write_text("# A page\n\n```python\nx = 1\n```\n\ntext\n\n```python\nassert x == 2\n```\n")
    with pytest.raises(AssertionError) as exc:
        runner.run(page, tmp_path)
    frame = exc.traceback[-1]
    assert Path(str(frame.path)).name == "broken.md" and frame.lineno + 1 == 10


def test_site_pages_link_only_existing_files():
    """Relative links of the site's own pages resolve (figures are made by the build)."""
    link = re.compile(r"\]\(([^)\s]+)\)")
    missing = []
    for page in SITE.rglob("*.md"):
        for target in link.findall(page.read_text()):
            path = target.split("#", 1)[0]
            if re.match(r"[a-z]+:", target) or not path or "_figures/" in path:
                continue
            if not (page.parent / path).exists():
                missing.append(f"{page.relative_to(SITE)}: {target}")
    assert not missing
