#!/usr/bin/env bash
# Build the Rust extension into the project's virtualenv (serialized: several people may build).
set -euo pipefail
cd "$(dirname "$0")/.."
[ -x .venv/bin/python ] || bash scripts/setup-venv.sh
exec 9>/tmp/ukflex-build.lock
flock 9
VIRTUAL_ENV="$PWD/.venv" PATH="$PWD/.venv/bin:$PATH" .venv/bin/maturin develop --release --quiet "$@"
