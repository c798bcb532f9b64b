#!/usr/bin/env bash
# Set up .venv, build the extension and the documentation site, run the Rust tests and the Python tests.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup-venv.sh
bash scripts/dev-build.sh
bash scripts/docs.sh   # the documentation site, warnings as errors (runs the tutorials' code)
cargo test --release
MPLBACKEND=Agg .venv/bin/python -m pytest -q "$@"
