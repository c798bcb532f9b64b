"""Run fuzz cases in a pool of worker processes with a watchdog.

Each worker takes batches ``(category, seed, n)`` from a queue and runs ``n`` hypothesis examples
of the category with that seed (generation only: a finding is recorded and the run goes on, so
counts are per case).  Before each case the worker writes the time and the case's ``repr`` into
shared memory; the parent kills a worker whose case has run longer than ``timeout`` seconds (a
*hang*, reported with that repr) and restarts it; a worker that dies on its own is a *crash*
(a panic that aborted, a segfault, the OOM killer).  One process per case would be safer but is
far too slow for 50k cases on two cores; one hang or crash costs only the rest of its batch.
"""

from __future__ import annotations

import json
import multiprocessing as mp
import os
import queue
import time
from collections import Counter, defaultdict
from dataclasses import dataclass, field
from typing import Dict, List, Optional, Tuple

REPR_BYTES = 4000


@dataclass
class Report:
    cases: Counter = field(default_factory=Counter)          # category -> cases run
    findings: Dict[str, Counter] = field(default_factory=lambda: defaultdict(Counter))  # category -> kind -> n
    samples: Dict[Tuple[str, str], List[str]] = field(default_factory=lambda: defaultdict(list))
    wall_time: float = 0.0
    workers: int = 0
    regression: Optional[str] = None

    #: every finding's detail (up to 1,000), for the JSON report; the text shows 5 per kind
    details: List[Tuple[str, str, str]] = field(default_factory=list)

    def add(self, category: str, kind: str, detail: str, keep: int = 5) -> None:
        self.findings[category][kind] += 1
        s = self.samples[(category, kind)]
        if len(s) < keep:
            s.append(detail)
        if len(self.details) < 1000:
            self.details.append((category, kind, detail))

    @property
    def total_findings(self) -> int:
        return sum(sum(c.values()) for c in self.findings.values())

    def table(self) -> str:
        kinds = ["crash", "hang", "panic", "unnamed-exception", "silent-nonfinite", "wrong", "cli-traceback"]
        head = f"| category | cases | {' | '.join(kinds)} |\n|---|---:|" + "---:|" * len(kinds)
        rows = [head]
        for cat in sorted(self.cases):
            rows.append(f"| {cat} | {self.cases[cat]} | "
                        + " | ".join(str(self.findings[cat][k]) for k in kinds) + " |")
        total = sum(self.cases.values())
        rows.append(f"| **all** | {total} | "
                    + " | ".join(str(sum(self.findings[c][k] for c in self.findings)) for k in kinds) + " |")
        return "\n".join(rows)

    def text(self) -> str:
        lines = [self.table(), "",
                 f"wall time {self.wall_time:.1f} s, {self.workers} workers"
                 + (f", seeded regression {self.regression!r}" if self.regression else "")]
        for (cat, kind), s in sorted(self.samples.items()):
            lines.append(f"\n{cat} / {kind}:")
            lines.extend(f"  - {d[:600]}" for d in s)
        return "\n".join(lines)

    def to_json(self) -> str:
        return json.dumps(dict(cases=dict(self.cases), findings={c: dict(k) for c, k in self.findings.items()},
                               samples={f"{c}/{k}": v for (c, k), v in self.samples.items()},
                               all_findings=[dict(category=c, kind=k, detail=d) for c, k, d in self.details],
                               wall_time=self.wall_time, workers=self.workers, regression=self.regression),
                          indent=1)


def _worker(wid, tasks, results, started, current, reprs, counts, regression):  # pragma: no cover - subprocess
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    os.environ["MPLBACKEND"] = "Agg"
    from hypothesis import HealthCheck, Phase, given, seed, settings

    from . import regressions
    from .cases import CATEGORIES

    import ukflex  # noqa: F401 - imported before the first case, so the watchdog never times an import

    if regression:
        os.environ["FUZZ_REGRESSION"] = regression  # for the processes a case starts (fuzz.cases._cli_subprocess)
        regressions.apply(regression)
    parent = os.getppid()
    while True:
        try:
            task = tasks.get(timeout=1.0)
        except queue.Empty:
            if os.getppid() != parent:  # the runner died (killed): do not run on as an orphan
                return
            continue
        if task is None:
            return
        task_id, cat, s, n = task
        current[wid] = task_id
        counts[wid] = 0
        category = CATEGORIES[cat]
        found: List[Tuple[str, str]] = []

        @settings(max_examples=n, database=None, deadline=None, phases=(Phase.generate,),
                  suppress_health_check=list(HealthCheck))
        @seed(s)
        @given(category.strategy())
        def prop(case):
            r = repr(case).encode("utf-8", "replace")[: REPR_BYTES - 1]
            reprs[wid * REPR_BYTES: wid * REPR_BYTES + len(r) + 1] = r + b"\0"
            started[wid] = time.time()
            try:
                for kind, detail in category.check(case):
                    found.append((kind, f"{detail} | case: {_clip(repr(case))}"))
            except BaseException as exc:  # noqa: BLE001 - a checker bug must not stop the run
                found.append(("checker-error", f"{type(exc).__name__}: {exc} | case: {_clip(repr(case))}"))
            started[wid] = 0.0
            counts[wid] += 1

        prop()
        results.put((wid, task_id, cat, int(counts[wid]), found))
        current[wid] = -1


def _clip(s: str, n: int = 1500) -> str:
    return s if len(s) <= n else s[: n - 3] + "..."


def run(cases: Dict[str, int], *, workers: int = 2, timeout: float = 10.0, seed: int = 0, batch: int = 25,
        regression: Optional[str] = None, progress: bool = False, wall_limit: Optional[float] = None) -> Report:
    """Run ``cases[category]`` cases of each category; return the :class:`Report`.

    ``wall_limit`` (s) stops handing out batches after that time (the report says how many cases ran).
    """
    # the same cases on every run: hash-based ordering inside the workers must not vary
    os.environ["PYTHONHASHSEED"] = "0"
    ctx = mp.get_context("spawn")
    tasks = ctx.Queue()
    results = ctx.Queue()
    started = ctx.Array("d", workers, lock=False)
    current = ctx.Array("i", [-1] * workers, lock=False)
    counts = ctx.Array("i", workers, lock=False)
    reprs = ctx.Array("c", REPR_BYTES * workers, lock=False)
    pending = {}
    k = 0
    for cat, n in cases.items():
        for i in range(0, n, batch):
            pending[k] = (k, cat, seed * 1_000_003 + k, min(batch, n - i))
            k += 1
    order = sorted(pending, key=lambda t: (t * 7919) % max(1, len(pending)))  # interleave categories
    for t in order:
        tasks.put(pending[t])
    report = Report(workers=workers, regression=regression)
    t0 = time.time()

    def spawn(wid):
        # not daemonic: a case may start processes of its own (sweep's process pool); a worker whose
        # runner died exits by itself (it watches its parent), and the runner kills its workers at the end
        p = ctx.Process(target=_worker, args=(wid, tasks, results, started, current, reprs, counts, regression),
                        daemon=False)
        p.start()
        return p

    procs = [spawn(w) for w in range(workers)]
    done = set()
    last_print = 0.0
    idle_deaths = 0  # workers that died before taking a case: a broken setup, not a finding
    try:
        while len(done) < len(pending):
            try:
                wid, task_id, cat, n, found = results.get(timeout=0.25)
                done.add(task_id)
                report.cases[cat] += n
                for kind, detail in found:
                    report.add(cat, kind, detail)
            except queue.Empty:
                pass
            now = time.time()
            for wid, p in enumerate(procs):
                task_id = current[wid]
                hung = started[wid] > 0 and now - started[wid] > timeout
                dead = not p.is_alive()
                if not (hung or dead) or (dead and task_id < 0):
                    if dead:  # finished between batches (should not happen) -> restart
                        idle_deaths += 1
                        if idle_deaths > 4 * workers:
                            raise RuntimeError(f"fuzz workers die before their first case (exit code {p.exitcode}): "
                                               "the worker setup (regression patch, import) fails")
                        procs[wid] = spawn(wid)
                    continue
                what = _repr_of(reprs, wid)
                if hung:
                    p.kill()
                p.join(5)
                if task_id >= 0 and task_id not in done:
                    _, cat, _, n = pending[task_id]
                    done.add(task_id)
                    report.cases[cat] += int(counts[wid]) + 1
                    kind = "hang" if hung else "crash"
                    detail = (f"> {timeout:g} s" if hung else f"exit code {p.exitcode}") + f" | case: {_clip(what)}"
                    report.add(cat, kind, detail)
                started[wid] = 0.0
                current[wid] = -1
                procs[wid] = spawn(wid)
            if wall_limit is not None and now - t0 > wall_limit:
                while True:  # drain the queue: what was not started is not counted
                    try:
                        t = tasks.get_nowait()
                        if t is not None:
                            done.add(t[0])
                    except queue.Empty:
                        break
                if all(current[w] < 0 for w in range(workers)):
                    break
            if progress and now - last_print > 5.0:
                last_print = now
                print(f"  {sum(report.cases.values())} cases, {report.total_findings} findings, "
                      f"{now - t0:.0f} s", flush=True)
    finally:
        for _ in procs:
            tasks.put(None)
        for p in procs:
            p.join(2)
            if p.is_alive():
                p.kill()
    report.wall_time = time.time() - t0
    return report


def _repr_of(reprs, wid: int) -> str:
    raw = bytes(reprs[wid * REPR_BYTES:(wid + 1) * REPR_BYTES])
    return raw.split(b"\0", 1)[0].decode("utf-8", "replace")
