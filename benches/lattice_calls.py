"""UK acceleration per call on the closed-loop lattice (scenes.lattice), sparse and dense paths
forced, both variants: independent rows (beams="links") and redundant ones (beams="continuous",
where the sparse path cannot certify full rank and falls back to the dense rank-revealing path).
Public API only; docs/scale.md.

    .venv/bin/python benches/lattice_calls.py [--sizes 6x4 4x16 16x4] [--reps 50]
"""

from __future__ import annotations

import argparse

from ukflex import scenes


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", nargs="+", default=["6x4", "4x16", "16x4"], help="COLUMNSxROWS")
    ap.add_argument("--reps", type=int, default=50)
    ap.add_argument("--batches", type=int, default=5)
    a = ap.parse_args()
    print("| lattice | beams | n | m | rank | sparse | dense | path taken by 'sparse' |")
    print("|---|---|---|---|---|---|---|---|")
    for beams in ("links", "continuous"):
        for size in a.sizes:
            w, h = (int(v) for v in size.split("x"))
            scene = scenes.lattice(columns=w, rows=h, beams=beams)
            times, path, rank = {}, "", 0
            for solver in ("sparse", "dense"):
                s = scene.build(uk_solver=solver)
                s.qdd(0.0, s.q0, s.qd0)
                times[solver] = s.time_acceleration(0.0, s.q0, s.qd0, reps=a.reps, batches=a.batches)
                info = s.rank_info()
                if solver == "sparse":
                    path, rank = info["uk_path"], info["rank"]
            print(f"| {w} x {h} | {beams} | {s.n_coords} | {s.n_constraints} | {rank} | "
                  f"{times['sparse'] * 1e6:.0f} us | {times['dense'] * 1e6:.0f} us | {path} |", flush=True)


if __name__ == "__main__":
    main()
