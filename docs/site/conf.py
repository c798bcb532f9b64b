"""Sphinx configuration of the documentation site (``bash scripts/docs.sh``).

The source directory is ``docs/``: the measurement pages (``docs/*.md``) are included where
they are, as "Background"; the site's own pages live in ``docs/site/``.

Why Sphinx (with MyST and autodoc + napoleon) rather than MkDocs: the docstrings are numpydoc
(``Parameters`` / ``Returns`` sections, ``:class:`` and ``:func:`` roles), which autodoc and
napoleon render as they are written, and ``-W`` turns every broken reference, bad docstring
markup and missing page into an error; MyST reads the existing Markdown pages unchanged,
including their GitHub-style section anchors; it is what NumPy, SciPy and most of the
scientific Python ecosystem use, so readers know the layout and ``objects.inv`` lets other
projects link ukflex's API.
"""

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "_ext"))

import ukflex  # noqa: E402  (the installed package: autodoc documents what users import)

project = "ukflex"
author = "the ukflex developers"
copyright = "the ukflex developers (MIT)"
release = version = ukflex.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",  # the docstrings are numpydoc style
    "myst_parser",
    "tutorials",  # runs the tutorials' code and writes their figures (docs/site/_ext/tutorials.py)
]
root_doc = "site/index"
source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
exclude_patterns = ["site/_ext/**", "site/_extra/**", "**/.pytest_cache/**"]

myst_heading_anchors = 3  # the background pages link to each other's sections (#anchors)
# scene-format.md shows JSON with comments and alternatives (`"a" | "b"`): pseudo-JSON that the
# highlighter cannot lex; it falls back to plain text, which is what those blocks are.
suppress_warnings = ["misc.highlighting_failure"]

autodoc_member_order = "bysource"
autodoc_default_options = {"members": True}
autodoc_typehints = "none"  # the numpydoc sections carry the types; ArrayLike would expand into a page of Unions
napoleon_google_docstring = False
napoleon_numpy_docstring = True
napoleon_use_param = False  # types as text: "(n_f,) sequence" is a shape, not a name to link
napoleon_use_rtype = False
napoleon_use_ivar = True  # "Attributes" as fields: autodoc documents the annotated attributes once

html_theme = "furo"
html_title = f"ukflex {release}"
html_extra_path = ["_extra"]  # index.html at the site's root: a redirect to site/index.html
html_show_sourcelink = False
