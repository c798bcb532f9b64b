"""Run the site's code: every ```python block of a page, in order, in one namespace.

One runner for two callers:

* the Sphinx build (``setup``): before reading, each page with code under ``docs/site/`` whose
  code changed since its last run is run in a fresh interpreter with ``docs/site/_figures/`` as
  its working directory, so the figures the page shows (``![...](../_figures/NAME.png)``) are
  made by the code it shows; a page whose code fails stops the build;
* the tests (``tests/test_tutorials.py``): each page run in a temporary directory, and every
  figure the page shows must have been written by its code.

    python docs/site/_ext/tutorials.py PAGE.md OUTDIR     # run one page by hand
"""

import hashlib
import os
import re
import subprocess
import sys
import time
from pathlib import Path

SITE = Path(__file__).resolve().parents[1]
FIGURES = SITE / "_figures"
_FENCE = re.compile(r"^```python[ \t]*\n(.*?)^```[ \t]*$", re.M | re.S)
_FIGURE = re.compile(r"_figures/([\w.-]+\.(?:png|gif|svg))")


def pages():
    """The site's pages that have Python code, in a stable order."""
    return sorted(p for p in SITE.rglob("*.md") if not p.name.startswith("_") and blocks(p))


def blocks(page):
    """``[(line, code), ...]``: the page's ```python blocks and the line each starts on."""
    text = Path(page).read_text()
    return [(text.count("\n", 0, m.start(1)) + 1, m.group(1)) for m in _FENCE.finditer(text)]


def figures(page):
    """The figure files a page shows (``_figures/NAME``), in order, without repeats."""
    return list(dict.fromkeys(_FIGURE.findall(Path(page).read_text())))


def run(page, workdir):
    """Execute a page's blocks in order in one namespace with ``workdir`` as working directory;
    returns the namespace.  An exception names the page and the block's line."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    page, blocks_ = Path(page).resolve(), blocks(page)
    namespace = {"__name__": "__main__"}
    here = os.getcwd()
    os.chdir(workdir)
    try:
        for line, code in blocks_:
            # pad with newlines so tracebacks give the line in the Markdown page
            exec(compile("\n" * (line - 1) + code, str(page), "exec"), namespace)
    finally:
        os.chdir(here)
        plt.close("all")
    return namespace


def _digest(page):
    return hashlib.sha256("\n".join(code for _, code in blocks(page)).encode()).hexdigest()


def _run_changed(app):
    """Sphinx hook: run every page whose code changed since the figures were made."""
    FIGURES.mkdir(exist_ok=True)
    for page in pages():
        stamp = FIGURES / f".{page.stem}.sha256"
        missing = [f for f in figures(page) if not (FIGURES / f).exists()]
        if stamp.exists() and stamp.read_text() == _digest(page) and not missing:
            continue
        start = time.perf_counter()
        proc = subprocess.run([sys.executable, __file__, str(page), str(FIGURES)], capture_output=True, text=True,
                              env={**os.environ, "MPLBACKEND": "Agg"})
        if proc.returncode != 0:
            raise RuntimeError(f"{page.relative_to(SITE)}: its code failed\n{proc.stdout}\n{proc.stderr}")
        missing = [f for f in figures(page) if not (FIGURES / f).exists()]
        if missing:
            raise RuntimeError(f"{page.relative_to(SITE)} shows figures its code does not write: {missing}")
        stamp.write_text(_digest(page))
        print(f"ran {page.relative_to(SITE)} ({time.perf_counter() - start:.1f} s)")


def _directory_links(app, doctree):
    """The background pages link folders of the repository (``../rust/body/``): a folder is no
    page and no download, so such a link keeps its text and loses the link (a file link becomes a
    download of the file, a page link a link to the page, as usual)."""
    from sphinx import addnodes

    base = (Path(app.srcdir) / app.env.docname).parent
    for node in list(doctree.findall(addnodes.pending_xref)):
        target = node.get("reftarget", "")
        if node.get("reftype") == "myst" and target.endswith("/") and (base / target).is_dir():
            node.replace_self(node.children)


def setup(app):
    app.connect("builder-inited", _run_changed)
    app.connect("doctree-read", _directory_links)
    return {"parallel_read_safe": True, "parallel_write_safe": True}


if __name__ == "__main__":
    run(sys.argv[1], sys.argv[2])
