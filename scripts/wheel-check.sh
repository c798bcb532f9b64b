#!/usr/bin/env bash
# Build the release wheel and check that it installs and runs without a Rust toolchain:
#   1. `maturin build --release` -> target/wheels/ukflex-*.whl (a manylinux, abi3 wheel: one file
#      for CPython >= 3.9 on this platform); its tag and metadata are checked;
#   2. a fresh venv gets the wheel with the [sweep] extra (no matplotlib: a base install for the
#      plots) by pip run under `env -i PATH=/usr/bin:/bin`, where neither cargo nor rustc is found
#      (checked), so nothing can compile;
#   3. from a temporary directory outside the tree, with the same clean environment: the README's
#      example (extracted from README.md as written), `ukflex --version`, `ukflex run pendulum`
#      (skips the plot with a note: no matplotlib), and a small sweep on a process pool.
# Not in CI (it compiles the extension once, and pip downloads NumPy, SciPy and Dask); time it with
# `time bash scripts/wheel-check.sh`.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$(pwd)
WORK=$(mktemp -d /tmp/ukflex-wheel-check.XXXXXX)
trap 'rm -rf "$WORK"' EXIT

[ -x .venv/bin/maturin ] || bash scripts/setup-venv.sh
step() { printf '\n== %s (%s)\n' "$1" "$(date +%T)"; }
# the interpreter of the fresh venv (a real path: it must start without PATH)
PY=$(${PYTHON:-python3} -c 'import sys; print(sys.executable)')

# the clean environment: no cargo, no rustc; pip's own settings and proxies are kept
CLEAN=(env -i "PATH=/usr/bin:/bin" "HOME=$HOME" "LANG=C.UTF-8" "MPLBACKEND=Agg" "PIP_DISABLE_PIP_VERSION_CHECK=1")
for v in $(compgen -e | grep -E '^(PIP_[A-Z_]+|https?_proxy|HTTPS?_PROXY|no_proxy|NO_PROXY|SSL_CERT_FILE)$' || true); do
    CLEAN+=("$v=${!v}")
done
clean() { "${CLEAN[@]}" "$@"; }

step "maturin build --release"
rm -f target/wheels/ukflex-*.whl
# serialized with scripts/dev-build.sh (several people may build on one machine)
flock /tmp/ukflex-build.lock .venv/bin/maturin build --release 2>&1 | grep -E "Built wheel|warning|error|manylinux|abi3" || true
WHEEL=$(ls target/wheels/ukflex-*.whl)
echo "$WHEEL ($(du -h "$WHEEL" | cut -f1))"
.venv/bin/python - "$WHEEL" <<'PY'
import os, re, sys, zipfile
path = sys.argv[1]
tag = os.path.basename(path)[:-4].split("-")[2:]          # python tag, abi tag, platform tag
assert tag[0] == "cp39" and tag[1] == "abi3", tag
assert re.match(r"manylinux_2_\d+_x86_64|manylinux2014_x86_64", tag[2]), tag
z = zipfile.ZipFile(path)
names = z.namelist()
text = z.read([n for n in names if n.endswith("METADATA")][0]).decode()
assert any(n.endswith("LICENSE") for n in names), "LICENSE missing from the wheel"
assert not any(n.startswith("studies/") for n in names), "the studies are not part of the wheel"
for field in ("License-Expression: MIT", "Provides-Extra: sweep", "Provides-Extra: plot", "Keywords:",
              "Requires-Python: >=3.9", "Classifier: Programming Language :: Python :: 3.9",
              "Classifier: Programming Language :: Python :: 3.13"):
    assert field in text, field
assert "Project-URL" not in text  # none invented
print("wheel tag", "-".join(tag), "| metadata OK:", len(names), "files")
PY

step "a clean environment: no Rust toolchain on PATH"
clean sh -c 'if command -v cargo || command -v rustc; then exit 1; fi' \
    || { echo "cargo or rustc found on the clean PATH"; exit 1; }
echo "command -v cargo, rustc: not found (PATH=/usr/bin:/bin)"

step "fresh venv + pip install WHEEL[sweep] (no compiler, no matplotlib)"
clean "$PY" -m venv "$WORK/venv"
clean "$WORK/venv/bin/pip" install --quiet "$WHEEL[sweep]"
clean "$WORK/venv/bin/python" -c 'import importlib.util as u; assert u.find_spec("matplotlib") is None; print("matplotlib: not installed (a base install for the plots)")'

step "the README example, from outside the tree"
awk '/^## Example/{f=1} f&&/^```python/{g=1;next} g&&/^```/{exit} g' README.md > "$WORK/readme_example.py"
[ -s "$WORK/readme_example.py" ] || { echo "no python block under '## Example' in README.md"; exit 1; }
(cd "$WORK" && clean "$WORK/venv/bin/python" - "$ROOT" <<'PY'
import runpy, sys, time, ukflex
assert not ukflex.__file__.startswith(sys.argv[1]), ukflex.__file__  # the installed copy, not the tree
print("ukflex", ukflex.__version__, "from", ukflex.__file__)
tic = time.perf_counter()
ns = runpy.run_path("readme_example.py")
res = ns["res"]
assert res.success and res.max_residual("position") < 1e-6, res.message  # interpolated outputs: ~2e-8
print(f"README example: {res.method}, {res.t.size} outputs, {1e3 * (time.perf_counter() - tic):.0f} ms (build, modes, run)")
PY
)

step "the console script"
(cd "$WORK" && clean "$WORK/venv/bin/ukflex" --version)
(cd "$WORK" && clean "$WORK/venv/bin/ukflex" run pendulum --t-end 0.5 --out "$WORK/out" | grep -E "^(note|settings|DOPRI5|auto|wrote)")
test -f "$WORK/out/pendulum.csv" && ! test -f "$WORK/out/pendulum.png"

step "a small sweep on a process pool"
(cd "$WORK" && clean "$WORK/venv/bin/python" - <<'PY'
import ukflex
df = ukflex.sweep(lambda length: ukflex.scenes.pendulum(length=length), {"length": [0.5, 1.0, 2.0]},
                  lambda r: {"theta_end": float(r.coordinate("rod.theta")[-1])}, "processes", workers=2,
                  t_end=0.2, method="DOPRI5")
assert (df["status"] == "ok").all(), df
print(df[["length", "theta_end", "status"]].to_string(index=False))
PY
)
step "all checks passed"
