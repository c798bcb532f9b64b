#!/usr/bin/env bash
# Set up .venv, build the extension, run the Rust tests and the Python tests.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup-venv.sh
bash scripts/dev-build.sh
cargo test --release
MPLBACKEND=Agg .venv/bin/python -m pytest -q "$@"
