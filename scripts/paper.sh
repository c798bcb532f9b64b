#!/usr/bin/env bash
# Set up .venv, build the extension and reproduce the paper's Fig. 4 into results/paper/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup-venv.sh
bash scripts/dev-build.sh
MPLBACKEND=Agg .venv/bin/ukflex paper --out results/paper "$@"
