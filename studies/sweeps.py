"""A parameter sweep of the slider-crank: crank speed x coupler diameter (docs/sweeps.md).

Every case is the paper's slider-crank (:func:`ukflex.scenes.slider_crank`) with a 2-element
nonlinear-strain FFRF coupler (the physically right FFRF model at speed,
docs/geometric-nonlinearity.md), crank speed ``omega`` and coupler diameter ``diameter``,
simulated for two crank revolutions from the undeformed start with ``method="auto"``.  Outputs:
the peak transverse midpoint deflection ``max |v(coupler, 0.5)|`` and the largest element axial
force ``max |N|`` over the run.

:func:`run_study` runs the same grid serially, on a local process pool and on a Dask
``LocalCluster`` in one go, checks that the three tables agree and writes ``sweep.csv``,
``timing.md`` and ``contours.png``::

    python -m studies sweeps --out docs/results/sweeps

Public API only (``ukflex.sweep``, ``ukflex.scenes``, ``SimulationResult``).
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import sys
import time
from typing import Any, Dict, List, Optional, Sequence

import numpy as np

import ukflex

__all__ = ["build", "outputs", "crank_study", "run_study", "OMEGAS", "DIAMETERS"]

#: Crank speeds [rad/s] (the paper: 124.8) and coupler diameters [m] (the paper: 6.35 mm): 40 x 25.
OMEGAS = list(np.linspace(40.0, 250.0, 40))
DIAMETERS = list(np.linspace(0.004, 0.010, 25))
REVOLUTIONS = 2.0


def build(omega: float, diameter: float) -> Any:
    """The case: the slider-crank and its simulate options (two crank revolutions)."""
    scene = ukflex.scenes.slider_crank(omega=omega, diameter=diameter, elements=2, strain="nonlinear")
    return scene, {"t_end": REVOLUTIONS * 2.0 * math.pi / omega}


def _states(res: Any) -> np.ndarray:
    """Positions as (nt, n) rows, from the orientation-free accessors."""
    return np.column_stack([res.coordinate(name) for name in res.system.coordinate_names])


def outputs(res: Any) -> Dict[str, float]:
    """Peak midpoint deflection [m] and largest axial force [N] of the coupler over the run."""
    _, v = res.beam_displacement("coupler", 0.5)
    axial = np.array([res.system.axial_forces("coupler", q) for q in _states(res)])
    return {"peak_deflection": float(np.max(np.abs(v))), "max_axial_force": float(np.max(np.abs(axial))),
            "steps": int(res.extra.get("naccept", len(res.t)))}


def crank_study(omegas: Sequence[float] = OMEGAS, diameters: Sequence[float] = DIAMETERS, executor: Any = "serial",
                workers: Optional[int] = None, progress: Optional[bool] = None) -> Any:
    """The sweep over ``omegas x diameters`` on ``executor`` (a DataFrame, see :func:`ukflex.sweep`)."""
    return ukflex.sweep(build, {"omega": list(omegas), "diameter": list(diameters)}, outputs, executor,
                        workers=workers, progress=progress)


def _contours(df: Any, path: str) -> None:
    from ukflex.results.plotting import figure

    fig = figure((11.0, 4.2), "the sweep's contour plot")
    from matplotlib.colors import LogNorm

    om = np.array(sorted(df["omega"].unique()))
    d = np.array(sorted(df["diameter"].unique()))
    axes = fig.subplots(1, 2)
    for ax, col, scale, label in ((axes[0], "peak_deflection", 1e3, "peak |v(coupler, 0.5)| [mm]"),
                                  (axes[1], "max_axial_force", 1.0, "max |axial force| [N]")):
        z = df.pivot(index="diameter", columns="omega", values=col).loc[d, om].to_numpy() * scale
        levels = np.geomspace(np.nanmin(z), np.nanmax(z), 13)
        cs = ax.contourf(om, d * 1e3, z, levels=levels, norm=LogNorm())
        ax.contour(om, d * 1e3, z, levels=levels, colors="k", linewidths=0.3)
        fig.colorbar(cs, ax=ax, label=label, format="%.3g")
        ax.axvline(124.8, color="w", lw=0.8, ls="--")
        ax.axhline(6.35, color="w", lw=0.8, ls="--")
        ax.set_xlabel("crank speed omega [rad/s]")
        ax.set_ylabel("coupler diameter [mm]")
        ax.set_title(label, fontsize=9)
    fig.suptitle(f"slider-crank, nonlinear FFRF coupler (2 elements), 2 revolutions: {len(df)} cases "
                 "(dashed: the paper's omega and d)", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def run_study(out: str, omegas: Sequence[float] = OMEGAS, diameters: Sequence[float] = DIAMETERS,
              workers: int = 2, executors: Sequence[str] = ("serial", "processes", "dask"),
              plot: bool = True) -> Dict[str, float]:
    """The same sweep on every executor in ``executors``, one after the other; write the table,
    the timings and the contour plot into ``out``.  Returns the wall time per executor [s]."""
    os.makedirs(out, exist_ok=True)
    times: Dict[str, float] = {}
    frames: Dict[str, Any] = {}
    load: List[str] = []
    for name in executors:
        load.append(f"{name} {os.getloadavg()[0]:.1f}" if hasattr(os, "getloadavg") else "")
        tic = time.perf_counter()
        if name == "dask":
            from distributed import Client, LocalCluster

            with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                              dashboard_address=None) as cluster, Client(cluster) as client:
                started = time.perf_counter()
                df = crank_study(omegas, diameters, client)
                times["dask (cases only)"] = time.perf_counter() - started
        else:
            df = crank_study(omegas, diameters, name, workers=workers)
        times[name] = time.perf_counter() - tic
        frames[name] = df
        print(f"{name}: {len(df)} cases in {times[name]:.1f} s, {df.attrs['failed']} failed", file=sys.stderr)
    first = frames[executors[0]]
    for name, df in frames.items():  # every executor computes the same numbers
        for col in ("peak_deflection", "max_axial_force"):
            a, b = first[col].to_numpy(), df[col].to_numpy()
            if not np.allclose(a, b, rtol=1e-12, atol=0.0, equal_nan=True):
                raise AssertionError(f"{name} differs from {executors[0]} in {col}")
    first.to_csv(os.path.join(out, "sweep.csv"), index=False)
    ok = first[first["status"] == "ok"]
    case = ok["wall_time"]
    lines = [
        f"# Sweep timing: {len(first)} cases (omega x diameter = {len(omegas)} x {len(diameters)})",
        "",
        f"Machine: {os.cpu_count()} cores (shared); workers: {workers}; run: "
        f"`python -m studies sweeps --out {out}`; 1-minute load average when each started: "
        f"{', '.join(load)}.",
        "",
        "| executor | wall time [s] | vs serial |",
        "|---|---:|---:|",
    ]
    base = times.get("serial")
    for name, t in times.items():
        lines.append(f"| {name} | {t:.1f} | {base / t:.2f}x |" if base else f"| {name} | {t:.1f} | - |")
    lines += [
        "",
        f"Per case (serial, build + simulate + outputs): median {statistics.median(case):.3f} s, "
        f"max {case.max():.3f} s; failed cases: {int((first['status'] == 'failed').sum())}; "
        f"unfinished: {int((first['status'] == 'unfinished').sum())}; methods: "
        + ", ".join(f"{m} {n}" for m, n in first["method"].value_counts().items()) + ".",
        "",
    ]
    with open(os.path.join(out, "timing.md"), "w") as fh:
        fh.write("\n".join(lines))
    if plot:
        _contours(first, os.path.join(out, "contours.png"))
    print("\n".join(lines))
    return times


def main(argv: Optional[List[str]] = None) -> int:
    p = argparse.ArgumentParser(prog="python -m studies sweeps", description=__doc__.split("\n\n")[0])
    p.add_argument("--out", required=True, help="output directory (sweep.csv, timing.md, contours.png)")
    p.add_argument("--workers", type=int, default=2, help="processes of the pool and of the LocalCluster (default 2)")
    p.add_argument("--small", action="store_true", help="8 x 5 cases instead of 40 x 25 (a check, ~10 s)")
    p.add_argument("--executors", default="serial,processes,dask", help="comma-separated (default all three)")
    a = p.parse_args(argv)
    om, d = (OMEGAS[::5], DIAMETERS[::6]) if a.small else (OMEGAS, DIAMETERS)
    run_study(a.out, om, d, workers=a.workers, executors=[e for e in a.executors.split(",") if e])
    return 0


if __name__ == "__main__":
    sys.exit(main())
