#!/usr/bin/env bash
# Create .venv with the Python build and runtime dependencies (idempotent).
set -euo pipefail
cd "$(dirname "$0")/.."
[ -x .venv/bin/python ] || python3 -m venv .venv
.venv/bin/python -m pip install --quiet --upgrade pip
.venv/bin/python -m pip install --quiet "maturin>=1.9.4,<2" "numpy>=1.24" "scipy>=1.10" "matplotlib>=3.7" "pytest>=8" "tomli>=1.1; python_version < '3.11'" \
    "dask[distributed]>=2023.1" "pandas>=1.5" "tqdm>=4.60" "threadpoolctl>=3.1" \
    "hypothesis>=6.80"  # the [sweep] extra (tests/test_sweep.py); hypothesis: the fuzz suite (tests/test_fuzz.py)
# the optional 'fe' extra (flexible bodies from planar meshes: ukflex.fe.from_mesh)
.venv/bin/python -m pip install --quiet "scikit-fem>=9" "meshio>=5"
