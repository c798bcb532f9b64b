"""``python -m studies spatial-fe-bar``: the free-free modes of a slender 3D FE bar
(:func:`ukflex.fe3.from_mesh`, quadratic tetrahedra) against the closed forms of bending in the
two planes (Euler-Bernoulli, free-free: ``beta_n L = 4.7300, 7.8532``) and of torsion
(Saint-Venant, rectangular section, free-free: ``f = k / (2 L) sqrt(G J / (rho I_p))``), mesh
by mesh (docs/spatial-flexible.md).

The bar: steel (E = 210 GPa, rho = 7850 kg/m^3, nu = 0.3), 1 m x 30 mm x 20 mm (L/h = 50, so
that shear and rotary inertia, which the 3D solid has and Euler-Bernoulli has not, lower the
second bending mode by well under 1 %). Each mode is told by its shape: the largest of the
cross-section means of ``u_x``, ``u_y``, ``u_z`` (axial, bending in y, bending in z) and of the
section rotation about the axis times the section's radius (torsion).
"""

from __future__ import annotations

import sys
import time
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

from ukflex import fe3

E, RHO, NU = 2.1e11, 7850.0, 0.3
L, B, H = 1.0, 0.03, 0.02
MESHES = ((10, 1, 1), (20, 2, 2), (40, 2, 2), (40, 3, 3), (60, 4, 4))
#: the compared modes: kind and its order within the kind
CASES = (("bend-z", 0), ("bend-z", 1), ("bend-y", 0), ("bend-y", 1), ("torsion", 0))


def closed_forms(length: float = L, width: float = B, height: float = H) -> Dict[str, List[float]]:
    """Free-free frequencies [Hz]: ``bend-z`` (bending in the x-z plane, I = b h^3 / 12),
    ``bend-y`` (I = h b^3 / 12), Euler-Bernoulli; ``torsion``, Saint-Venant with the series of the
    rectangle's torsion constant."""
    area = width * height
    beta = (4.7300407949, 7.8532046241)
    g = E / (2.0 * (1.0 + NU))

    def bending(i: float) -> List[float]:
        return [bl ** 2 / (2 * np.pi * length ** 2) * np.sqrt(E * i / (RHO * area)) for bl in beta]

    a, c = max(width, height) / 2, min(width, height) / 2
    series = sum(np.tanh(n * np.pi * a / (2 * c)) / n ** 5 for n in range(1, 400, 2))
    j = (2 * c) ** 3 * (2 * a) / 3 * (1 - 192 / np.pi ** 5 * c / a * series)
    ip = area * (width ** 2 + height ** 2) / 12
    return {"bend-z": bending(width * height ** 3 / 12), "bend-y": bending(height * width ** 3 / 12),
            "torsion": [k / (2 * length) * np.sqrt(g * j / (RHO * ip)) for k in (1, 2)]}


def classify(data: fe3.FlexibleData3) -> List[str]:
    """The kind of each kept mode (module docs)."""
    x, nodes = data.info["modes"], data.info["nodes"]
    xs = np.round(nodes[:, 0], 9)
    y, z = nodes[:, 1], nodes[:, 2]
    r = np.sqrt(y * y + z * z).max()
    kinds = []
    for col in range(x.shape[1]):
        u = x[:, col].reshape(-1, 3)
        m = np.zeros(4)
        for v in np.unique(xs):
            s = xs == v
            rot = np.sum(y[s] * u[s, 2] - z[s] * u[s, 1]) / np.sum(y[s] ** 2 + z[s] ** 2)
            m = np.maximum(m, [abs(u[s, 0].mean()), abs(u[s, 1].mean()), abs(u[s, 2].mean()), abs(rot) * r])
        kinds.append(("axial", "bend-y", "bend-z", "torsion")[int(np.argmax(m))])
    return kinds


def bar(cells: Sequence[int], modes: int = 10) -> fe3.FlexibleData3:
    """The free-free reduced bar on a ``cells`` mesh of quadratic tetrahedra."""
    return fe3.from_mesh(fe3.bar_mesh(L, B, H, cells), density=RHO, youngs_modulus=E, poisson_ratio=NU,
                         interfaces={"A": {"point": (0.0, 0.0, 0.0)}}, modes=modes)


def compare(data: fe3.FlexibleData3) -> Dict[Tuple[str, int], Tuple[float, float]]:
    """``(kind, order) -> (FE, closed form)`` for the compared modes."""
    kinds, f = classify(data), data.info["frequencies"]
    ref = closed_forms()
    out = {}
    for kind, k in CASES:
        found = [fi for ki, fi in zip(kinds, f) if ki == kind]
        out[kind, k] = (float(found[k]) if len(found) > k else float("nan"), ref[kind][k])
    return out


def report(meshes: Sequence[Sequence[int]] = MESHES) -> str:
    lines = ["| mesh (nx, ny, nz) | nodes | build [s] | " + " | ".join(f"{k} {i + 1}" for k, i in CASES) + " |",
             "|---|---:|---:|" + "---:|" * len(CASES)]
    ref = closed_forms()
    lines.insert(0, "closed form [Hz]: " + ", ".join(f"{k} {i + 1} = {ref[k][i]:.2f}" for k, i in CASES))
    for cells in meshes:
        t0 = time.perf_counter()
        d = bar(cells)
        dt = time.perf_counter() - t0
        c = compare(d)
        errs = " | ".join(f"{c[k][0]:.2f} ({100 * (c[k][0] / c[k][1] - 1):+.2f} %)" for k in CASES)
        lines.append(f"| {tuple(cells)} | {d.info['nodes'].shape[0]} | {dt:.1f} | {errs} |")
        print(lines[-1], file=sys.stderr)
    return "\n".join(lines)


def main(argv: Optional[List[str]] = None) -> int:
    print(report())
    return 0
