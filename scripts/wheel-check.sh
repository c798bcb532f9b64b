#!/usr/bin/env bash
# Build the release wheel and check that ukflex installs and works from outside the source tree:
#   1. `maturin build --release` -> target/wheels/ukflex-*.whl, installed into a fresh venv;
#   2. `pip install .` (from the source tree) into another fresh venv;
#   3. `pip install .[sweep]` into a third, with a tiny sweep on a process pool.
# Each venv imports ukflex from a temporary directory (not the tree), prints the version and runs a
# short simulation; without the [plot] extra, plotting must fail with MissingDependencyError.
# Not in CI (it compiles the extension three times); time it with `time bash scripts/wheel-check.sh`.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$(pwd)
PY=${PYTHON:-python3}
WORK=$(mktemp -d /tmp/ukflex-wheel-check.XXXXXX)
trap 'rm -rf "$WORK"' EXIT
export PIP_DISABLE_PIP_VERSION_CHECK=1

[ -x .venv/bin/maturin ] || bash scripts/setup-venv.sh
step() { printf '\n== %s (%s)\n' "$1" "$(date +%T)"; }

SMOKE='
import os, sys, ukflex
assert not ukflex.__file__.startswith(sys.argv[1]), ukflex.__file__  # installed copy, not the tree
res = ukflex.simulate(ukflex.scenes.pendulum(), 0.5, method="DOPRI5", rtol=1e-9)
e = res.energy()
assert res.success and abs(e[-1] - e[0]) < 1e-6, (res.message, e[0], e[-1])
print("ukflex", ukflex.__version__, "from", os.path.dirname(ukflex.__file__), "| pendulum 0.5 s:", res.method,
      "energy drift %.1e" % abs(e[-1] - e[0]))
try:
    import matplotlib  # noqa: F401
except ImportError:
    from ukflex.results.animate import animate
    try:
        animate(res, "x.gif")
    except ukflex.MissingDependencyError as exc:
        print("without matplotlib:", exc)
    else:
        raise SystemExit("plotting without matplotlib did not raise MissingDependencyError")
'

check() {  # venv, label
    (cd "$WORK" && "$1/bin/python" -c "$SMOKE" "$ROOT")
    (cd "$WORK" && "$1/bin/ukflex" run pendulum --t-end 0.1 --no-plot --out "$WORK/out-$2" > /dev/null)
    echo "ukflex run (console script) OK"
}

step "maturin build --release"
rm -f target/wheels/ukflex-*.whl
.venv/bin/maturin build --release --quiet 2>&1 | tail -n 2
WHEEL=$(ls target/wheels/ukflex-*.whl)
echo "$WHEEL"
.venv/bin/python - "$WHEEL" <<'PY'
import sys, zipfile
names = zipfile.ZipFile(sys.argv[1]).namelist()
meta = [n for n in names if n.endswith("METADATA")][0]
text = zipfile.ZipFile(sys.argv[1]).read(meta).decode()
assert any(n.endswith("LICENSE") for n in names), "LICENSE missing from the wheel"
for field in ("License-Expression: MIT", "Provides-Extra: sweep", "Provides-Extra: plot", "Keywords:", "Classifier:"):
    assert field in text, field
print("wheel metadata OK:", len(names), "files")
PY

step "fresh venv + the wheel"
$PY -m venv "$WORK/v-wheel"
"$WORK/v-wheel/bin/pip" install --quiet "$WHEEL"
check "$WORK/v-wheel" wheel

step "fresh venv + pip install ."
$PY -m venv "$WORK/v-src"
"$WORK/v-src/bin/pip" install --quiet "$ROOT"
check "$WORK/v-src" src

step "fresh venv + pip install .[sweep]"
$PY -m venv "$WORK/v-sweep"
"$WORK/v-sweep/bin/pip" install --quiet "$ROOT[sweep]"
check "$WORK/v-sweep" sweep
(cd "$WORK" && "$WORK/v-sweep/bin/python" - <<'PY'
import ukflex
df = ukflex.sweep(lambda length: ukflex.scenes.pendulum(length=length), {"length": [0.5, 1.0, 2.0]},
                  lambda r: {"theta_end": float(r.coordinate("rod.theta")[-1])}, "processes", workers=2,
                  t_end=0.2, method="DOPRI5")
assert (df["status"] == "ok").all(), df
print(df[["length", "theta_end", "status"]].to_string(index=False))
PY
)
step "all checks passed"
