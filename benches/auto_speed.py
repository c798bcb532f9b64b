"""Is ``method="auto"`` the fast way to the physical answer on scenes nobody tuned it for?

Every built-in flexible scene, each built as an FFRF and as an ANCF model of 4 elements, run by
``simulate()`` on a freshly built System (the whole call timed: auto's modal analysis, the run
and the result at 401 outputs), side by side with the other ways ukflex can run it: auto at
looser tolerances, RADAU5M at fixed steps around auto's and error-controlled, GENALPHA at fixed
steps, DOPRI5.  Medians of interleaved repetitions, one run.  The ratios are taken on the call's
CPU time (``time.process_time``; the core runs on one thread): on a machine shared by more jobs
than cores the wall clock of a millisecond call is much of it the wait for a core (1.9x its CPU
time on average, up to 5.6x, at load 5 on 2 cores); the wall-clock medians are in the csv beside them.

Errors are measured against the **physical** answer: a converged, independent model of the same
scene (the ANCF cable of 32 elements at a fine fixed step; for the paper's slider-crank, Exudyn's
converged ANCF cable, benches/data/exudyn_ref_ancf.csv); the largest deviation of the scene's
output over the run, relative to the output's largest value.  The integration error (against the
same model at a fine step) is given beside it.  The output is the elastic field where one point
would hide part of it: the four-bar's coupler deflection at its quarter, mid and three-quarter
points (the mid-point alone misses the second, antisymmetric bending mode), the spinning beam's
points off the hub's axis at a quarter, half, three quarters and the tip.

For each model: auto's time and error, and the fastest configuration whose physical error is
within 1.1 x auto's (the same error, to the digit that matters), whose integration error is
within that level too (its agreement does not rest on its own error cancelling the model's:
``fastest_at``) and whose next finer setting is too (reliable); the ratio auto / fastest
(target: at most 2).  The pick by the physical error alone (the earlier criterion) is printed
beside it.

    python benches/auto_speed.py             # ~5 min: the table of docs/integrators.md, benches/data/auto_speed.csv
    python benches/auto_speed.py --quick     # ~2 min: 2 repetitions, fewer configurations
    python benches/auto_speed.py --elements 8  # the same scenes on 8 elements (model error ~5x smaller)

Repetitions: ``--repeat`` of every configuration, and more of those that might be the fastest
(at most ``SHORT`` times auto's first call) on the short scenes, until they fill ~``MIN_SWEEP`` s of
interleaved calls (at most ``MAX_REPEAT`` repetitions): on the 0.02 s pinned beam (calls under
1 ms) medians of 5 moved the ratio between 1.7 and 2.7 from run to run.

The references are computed once and kept in benches/data/auto_speed_refs.npz (delete it to
recompute: ~3 min more).
"""

from __future__ import annotations

import argparse
import csv
import math
import os
import statistics
import time
import warnings

import numpy as np

import ukflex
from ukflex import scenes

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.join(HERE, "data")
REFS = os.path.join(DATA, "auto_speed_refs.npz")
NOUT = 401
N_MODEL, N_REF = 4, 32  # the table's model (``--elements``) and the physical reference's cable
MIN_SWEEP, MAX_REPEAT, SHORT = 1.0, 41, 3.0  # CPU seconds of repetitions; repetitions at most; which repeat
SAME = 1.1  # "the same error": within this factor of auto's
BUDGET = 5.0  # seconds per run: slower configurations are out of the race


# ---------------------------------------------------------------------------- outputs
def _v_mid(body, length):
    return lambda system, res: res.beam_displacement(body, 0.5)[1] / length


#: where the four-bar's coupler deflection is read: the mid-point alone misses the second,
#: antisymmetric bending mode (no displacement there), which the crank's drive sets off
FIELD_POINTS = (0.25, 0.5, 0.75)
SPIN_POINTS = (0.25, 0.5, 0.75, 1.0)


def _v_field(body, length):
    """The transverse deflection at :data:`FIELD_POINTS`, shape (3, nt): the elastic field."""
    return lambda system, res: np.array([res.beam_displacement(body, xi)[1] / length for xi in FIELD_POINTS])


def _tip_y(system, res):
    return res.beam_position("beam", 1.0)[1]


def _field_off_hub_axis(system, res):
    """The beam's points at :data:`SPIN_POINTS` off the hub's axis, shape (4, nt): the elastic
    field (the tip alone lets a coarse step's error cancel the model's there)."""
    th = res.q[system.coordinate_index("hub.theta")]
    out = []
    for xi in SPIN_POINTS:
        x, y = res.beam_position("beam", xi)
        out.append(-np.sin(th) * x + np.cos(th) * y)
    return np.array(out)


def _tip_off_root_tangent(system, res):
    """The rod's tip off the line along its root tangent (the bending; the swing taken out)."""
    q = res.q
    p0 = system.beam_point("rod", 0.0, q)
    p1 = system.beam_point("rod", 1.0, q)
    if system.body_kind("rod") == "cable":
        frame = np.arctan2(p1[1] - p0[1], p1[0] - p0[0])  # the chord frame
    else:
        frame = q[system.coordinate_index("rod.theta")]
    tangent = frame + p0[4]
    dx, dy = p1[0] - p0[0], p1[1] - p0[1]
    return -np.sin(tangent) * dx + np.cos(tangent) * dy


def _scene(kind, formulation, elements):
    """(Scene, t_end, output) of one built-in scene as a model of ``formulation``, ``elements``."""
    f = formulation
    if kind == "slider_crank":
        kw = {"strain": "nonlinear"} if f == "ffrf" else {}
        return (scenes.slider_crank(theory="euler-bernoulli", elements=elements, formulation=f, **kw), 0.1,
                _v_mid("coupler", scenes.PAPER["coupler_length"]))
    if kind == "four_bar":
        return (scenes.four_bar(theory="euler-bernoulli", elements=elements, formulation=f), 0.63,
                _v_field("coupler", 0.3))
    if kind == "cantilever":
        return scenes.cantilever(elements=elements, formulation=f), 0.8, _tip_y
    if kind == "pinned_beam":
        return (scenes.pinned_beam(elements=elements, formulation=f, gravity=True), 0.02,
                _v_mid("beam", scenes.PAPER["coupler_length"]))
    if kind == "spin_up":
        return scenes.spin_up(elements=elements, formulation=f), 20.0, _field_off_hub_axis
    if kind == "flexible_pendulum":
        return scenes.flexible_pendulum(elements=elements, formulation=f), 1.5, _tip_off_root_tangent
    raise ValueError(kind)


KINDS = ("slider_crank", "four_bar", "cantilever", "pinned_beam", "spin_up", "flexible_pendulum")


def _run(kind, formulation, elements, method, budget=BUDGET, **kw):
    scene, T, output = _scene(kind, formulation, elements)
    te = np.linspace(0.0, T, NOUT)
    system = scene.build()
    cpu, tic = time.process_time(), time.perf_counter()
    res = ukflex.simulate(system, T, method=method, t_eval=te, max_wall_time=budget, **kw)
    wall, cpu = time.perf_counter() - tic, time.process_time() - cpu
    y = output(system, res) if res.status == 0 else None
    return (cpu, wall), y, res


def _exudyn_reference(te):
    rows = [ln for ln in open(os.path.join(DATA, "exudyn_ref_ancf.csv")) if not ln.startswith("#")]
    data = np.array([[float(v) for v in ln.split(",")] for ln in rows[1:]])
    return np.interp(te, data[:, 0], data[:, 1])


def references(kinds, elements=N_MODEL):
    """{kind: (physical reference, {formulation: same-model fine run})}, computed once (cached);
    the same-model runs of a model of ``elements`` other than :data:`N_MODEL` are kept apart."""
    cached = dict(np.load(REFS)) if os.path.exists(REFS) else {}
    out = {}
    for kind in kinds:
        tag = f"{kind}@field" if kind in ("four_bar", "spin_up") else kind  # the cache of the single-point output stays apart
        model = "" if elements == N_MODEL else f"@n{elements}"
        keys = [f"{tag}/physical", f"{tag}/ffrf{model}", f"{tag}/ancf{model}"]
        if not all(k in cached for k in keys):
            print(f"# reference of {kind} ...", flush=True)
            T = _scene(kind, "ancf", N_MODEL)[1]
            te = np.linspace(0.0, T, NOUT)
            if keys[0] in cached:
                pass
            elif kind == "slider_crank":
                cached[keys[0]] = _exudyn_reference(te)
            else:
                h = ukflex.simulate(_scene(kind, "ancf", N_REF)[0].build(), T).extra["auto"]["step"]
                _, y, res = _run(kind, "ancf", N_REF, "RADAU5M", budget=None, step=h / 8, rtol=1e-9)
                assert res.status == 0, res.message
                cached[keys[0]] = y
            for f in ("ffrf", "ancf"):
                h = ukflex.simulate(_scene(kind, f, elements)[0].build(), T).extra["auto"]["step"]
                _, y, res = _run(kind, f, elements, "RADAU5M", budget=None, step=h / 16, rtol=1e-10)
                assert res.status == 0, res.message
                cached[f"{tag}/{f}{model}"] = y
            np.savez(REFS, **cached)
        out[kind] = (cached[keys[0]], {f: cached[f"{tag}/{f}{model}"] for f in ("ffrf", "ancf")})
    return out


def configurations(h, quick):
    """(series, label, method, options); a series lists its settings coarse to fine."""
    cfg = [("auto", "auto (default)", "auto", {})]
    for r in ((1e-3, 1e-4, 1e-5) if not quick else (1e-4,)):
        cfg.append(("auto rtol", f"auto rtol {r:g}", "auto", {"rtol": r}))
    for k in ((4, 2, 1, 0.5, 0.25) if not quick else (2, 1, 0.5)):
        cfg.append(("RADAU5M h", f"RADAU5M h = {k:g} h_auto", "RADAU5M", {"step": k * h, "rtol": 1e-4}))
    for r in ((1e-2, 1e-3, 1e-4, 1e-5) if not quick else (1e-3, 1e-4)):
        cfg.append(("RADAU5M rtol", f"RADAU5M rtol {r:g}", "RADAU5M", {"rtol": r}))
    for k in ((1, 0.5, 0.25, 0.125, 0.0625) if not quick else (0.5, 0.25, 0.125)):
        cfg.append(("GENALPHA h", f"GENALPHA h = {k:g} h_auto", "GENALPHA", {"step": k * h}))
    for r in ((1e-3, 1e-5, 1e-7) if not quick else (1e-4,)):
        cfg.append(("DOPRI5", f"DOPRI5 rtol {r:g}", "DOPRI5", {"rtol": r}))
    return cfg


def fastest_at(table, auto, own):
    """The fastest configuration of ``table`` (rows ``(series, label, seconds, result)``, each
    series coarse to fine) at auto's physical error: within :data:`SAME` of it, and so is the
    next finer setting of its series (reliable).  ``own``: its integration error too, so that
    the agreement does not rest on its own error cancelling the model's (GENALPHA at 1/8 of
    auto's step on the spinning ANCF cable of 4 elements: 8.1e-4 off the physical answer with an
    integration error of 1.6e-3; on the cable of 8 elements 1.5e-3, where auto is 5.9e-5)."""
    level = SAME * auto[3][1]

    def ok(r):
        return r[1] <= level and (not own or r[2] <= level)

    best = None
    for i, (series, label, t, r) in enumerate(table):
        finer = next((x for x in table[i + 1:] if x[0] == series), None)
        if ok(r) and (finer is None or ok(finer[3]) or series.startswith("auto")) and (best is None or t < best[2]):
            best = (series, label, t, r)
    return best


def wall_ratio(walls, auto, best):
    """auto / fastest by the medians of the wall-clock times (the ratio is taken on CPU times)."""
    return statistics.median(w for _, w in walls[auto[1]]) / statistics.median(w for _, w in walls[best[1]])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--kinds", default=",".join(KINDS))
    ap.add_argument("--elements", type=int, default=N_MODEL)
    args = ap.parse_args()
    n_model = args.elements
    warnings.simplefilter("ignore")
    kinds = args.kinds.split(",")
    repeat = 2 if args.quick else args.repeat
    refs = references(kinds, n_model)
    rows = []
    summary = []
    for kind in kinds:
        phys, same = refs[kind]
        peak = np.abs(phys).max()
        for f in ("ffrf", "ancf"):
            scene, T, _ = _scene(kind, f, n_model)
            h = ukflex.simulate(scene.build(), T).extra["auto"].get("step") or T / 200
            cfg = configurations(h, args.quick)
            walls = {c[1]: [] for c in cfg}  # (cpu, wall) per repetition
            result = {}
            reps, rep, short = repeat, 0, None
            while rep < reps:
                for series, label, method, kw in (cfg if rep % 2 == 0 else cfg[::-1]):
                    if label in result and result[label] is None:
                        continue  # failed or over budget once: out
                    if rep >= repeat and label not in short:
                        continue  # far slower than auto: not the fastest at its error
                    wall, y, res = _run(kind, f, n_model, method, **kw)
                    if y is None:
                        result[label] = None
                        continue
                    walls[label].append(wall)
                    err = float(np.abs(y - phys).max() / peak)
                    ierr = float(np.abs(y - same[f]).max() / peak)
                    a = res.extra.get("auto") or {}
                    result[label] = (series, err, ierr, res.method, a.get("floor"), a.get("step"),
                                     res.extra.get("naccept"), res.extra.get("nreject"))
                rep += 1
                if rep == 1 and not args.quick:  # short scenes: more repetitions of the short calls
                    first = walls["auto (default)"][0][0] if walls["auto (default)"] else math.inf
                    short = {k for k, v in walls.items() if v and v[0][0] <= SHORT * first}
                    sweep = sum(walls[k][0][0] for k in short)
                    reps = max(repeat, min(MAX_REPEAT, math.ceil(MIN_SWEEP / max(sweep, 1e-9))))
            table = []
            for series, label, method, kw in cfg:
                r = result.get(label)
                if r is None:
                    rows.append([kind, f, label, "", "", "", "", "failed or over budget"])
                    continue
                t = statistics.median(c for c, _ in walls[label])
                table.append((series, label, t, r))
                rows.append([kind, f, label, f"{1e3 * t:.2f}", f"{1e3 * statistics.median(w for _, w in walls[label]):.2f}",
                             f"{r[1]:.3e}", f"{r[2]:.3e}",
                             f"{r[3]} steps {r[6]} rejected {r[7]}" + (f" floor {r[4]:.2e}" if r[4] else "")])
            auto = next(x for x in table if x[1] == "auto (default)")
            best, by_physical = fastest_at(table, auto, own=True), fastest_at(table, auto, own=False)
            summary.append((kind, f, auto, best, by_physical))
            print(f"{kind:18} {f:5} auto {1e3 * auto[2]:8.2f} ms CPU  err {auto[3][1]:.2e} (integration {auto[3][2]:.1e}, "
                  f"{auto[3][3]}, {auto[3][6]} steps, {auto[3][7]} rejected; {reps} repetitions)  fastest at that error: {best[1]} "
                  f"{1e3 * best[2]:.2f} ms ({best[3][1]:.2e}, integration {best[3][2]:.1e})  ratio {auto[2] / best[2]:.2f}"
                  f" (wall {wall_ratio(walls, auto, best):.2f})"
                  f"  [by the physical error alone: {by_physical[1]}, ratio {auto[2] / by_physical[2]:.2f}]", flush=True)
    name = "auto_speed.csv" if n_model == N_MODEL else f"auto_speed_n{n_model}.csv"
    with open(os.path.join(DATA, name), "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["scene", "formulation", "configuration", "median CPU ms", "median wall ms", "physical error",
                    "integration error", "notes"])
        w.writerows(rows)
    print()
    print("| scene | model | auto: CPU ms, physical error (integration) | fastest at auto's error (integration) | ratio "
          "| by the physical error alone: fastest, ratio |")
    print("|---|---|---|---|---|---|")
    for kind, f, auto, best, phys in summary:
        print(f"| {kind} | {f.upper()} N = {n_model} | {1e3 * auto[2]:.1f} ms, {auto[3][1]:.2e} ({auto[3][2]:.1e}) | "
              f"{best[1]}: {1e3 * best[2]:.1f} ms, {best[3][1]:.2e} ({best[3][2]:.1e}) | {auto[2] / best[2]:.2f} | "
              f"{phys[1]}: {1e3 * phys[2]:.1f} ms, {auto[2] / phys[2]:.2f} |")


if __name__ == "__main__":
    main()
