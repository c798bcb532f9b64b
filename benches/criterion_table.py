"""Print the medians (and mean, MAD) of the last `cargo bench` criterion runs as a table.

    cargo bench --bench uk && cargo bench --bench svd
    python3 benches/criterion_table.py [target/criterion]

Criterion's console line shows the slope/mean estimate; the performance targets are stated
for the median, which is read here from target/criterion/<group>/<bench>/new/estimates.json.
Growth exponents (least-squares slope of log median vs log size) are printed for the
`elements` (N) and `chain` (K) groups.
"""
import json
import math
import sys
from pathlib import Path


def fmt(ns):
    if ns >= 1e6:
        return f"{ns / 1e6:9.3f} ms"
    if ns >= 1e3:
        return f"{ns / 1e3:9.3f} us"
    return f"{ns:9.1f} ns"


def slope(pts):
    xs = [math.log(x) for x, _ in pts]
    ys = [math.log(y) for _, y in pts]
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)


def main():
    root = Path(sys.argv[1] if len(sys.argv) > 1 else "target/criterion")
    rows = []
    for est in sorted(root.glob("**/new/estimates.json")):
        bench = json.loads((est.parent / "benchmark.json").read_text())
        d = json.loads(est.read_text())
        rows.append((bench["full_id"], d["median"]["point_estimate"], d["mean"]["point_estimate"],
                     d["median_abs_dev"]["point_estimate"]))
    print(f"{'benchmark':48s} {'median':>12s} {'mean':>12s} {'MAD':>12s}")
    for name, med, mean, mad in rows:
        print(f"{name:48s} {fmt(med)} {fmt(mean)} {fmt(mad)}")
    for group in ("elements", "chain"):
        pts = sorted((int(n.split("/")[1]), med) for n, med, _, _ in rows if n.startswith(group + "/"))
        if len(pts) > 2:
            tail = [p for p in pts if p[0] >= 8]
            extra = f", {group} >= 8: {slope(tail):.2f}" if len(tail) > 2 else ""
            print(f"growth exponent of the median, {group} {pts[0][0]}..{pts[-1][0]}: {slope(pts):.2f}{extra}")


if __name__ == "__main__":
    main()
