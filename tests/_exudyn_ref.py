"""The geometrically exact reference of the paper scene (Exudyn's converged ANCF cable,
benches/data/exudyn_ref_ancf.csv): the midpoint deflection v(0.5)/Lb over 0..0.1 s."""

import pathlib

import numpy as np

DATA = pathlib.Path(__file__).resolve().parent.parent / "benches" / "data"


def exudyn_reference(name="exudyn_ref_ancf.csv"):
    """``(t, v)`` of a reference file in benches/data."""
    t, v = [], []
    for line in (DATA / name).read_text().splitlines():
        if line.startswith("#") or line.startswith("t,"):
            continue
        a, b = line.split(",")
        t.append(float(a))
        v.append(float(b))
    return np.array(t), np.array(v)
