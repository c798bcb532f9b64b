"""Per-call UK kernel on the spatial slider-crank (and A04, the heavy top, the flyball
governor), timed inside Rust (System.time_acceleration: best of batches, per call), as the
process CPU time of those calls (time.process_time around them: what a loaded machine does not
inflate by preemption), and from Python (System.qdd).
Run: .venv/bin/python benches/spatial_kernel.py
     .venv/bin/python benches/spatial_kernel.py --export   (rewrites benches/data/spatial/*.json,
     the descriptions the criterion bench `cargo bench --bench spatial` reads)"""
import json, sys, pathlib, time
import numpy as np
import ukflex
from ukflex.reference import spatial as sp
ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))
from test_spatial import to_description  # noqa: E402

SCENES = [("slider_crank", sp.scenes.slider_crank), ("bricard", sp.scenes.bricard),
          ("heavy_top", lambda: sp.scenes.heavy_top(spin=30.0)), ("flyball", sp.scenes.flyball_governor)]

if "--export" in sys.argv:
    out = ROOT / "benches" / "data" / "spatial"
    out.mkdir(parents=True, exist_ok=True)
    for name, make in SCENES:
        (out / f"{name}.json").write_text(json.dumps(to_description(make()), indent=1) + "\n")
        print("wrote", out / f"{name}.json")
    sys.exit(0)

for name, make in SCENES:
    system = ukflex.System(to_description(make()))
    q, qd = system.q0, system.qd0
    c0 = time.process_time()
    rust = system.time_acceleration(0.1, q, qd, 20000, 7) * 1e6
    cpu = (time.process_time() - c0) / (7 * 20000) * 1e6
    reps = 20000
    t0 = time.perf_counter()
    for _ in range(reps):
        system.qdd(0.1, q, qd)
    py = (time.perf_counter() - t0) / reps * 1e6
    print(f"{name:13s} n={system.n_coords:3d} m={system.n_constraints:3d}  Rust {rust:7.2f} us/call (CPU {cpu:7.2f})   Python System.qdd {py:7.2f} us/call")
