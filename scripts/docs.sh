#!/usr/bin/env bash
# Build the documentation site into _site/ (git-ignored; open _site/index.html), warnings as errors.
# Sets up .venv and builds the extension if needed (autodoc imports ukflex), installs the docs
# requirements from PyPI, runs the pages whose code changed (their figures: docs/site/_figures/;
# delete that folder to run every page again, e.g. after a change of the library).
set -euo pipefail
cd "$(dirname "$0")/.."
[ -x .venv/bin/python ] || bash scripts/setup-venv.sh
.venv/bin/python -c "import ukflex._core" 2>/dev/null || bash scripts/dev-build.sh
.venv/bin/python -m pip install --quiet "sphinx>=7.2,<10" "myst-parser>=3" "furo>=2024.1"
MPLBACKEND=Agg .venv/bin/python -m sphinx -W --keep-going -q -c docs/site docs _site "$@"
echo "docs: _site/index.html"
