"""Parameter sweeps: one simulation per case, serial, on a local process pool or on Dask.

:func:`sweep` runs ``build(**case)`` -> simulate -> ``outputs(result)`` for every case of a grid
and returns a pandas DataFrame with one row per case.  The same call runs

* ``executor="serial"``: in this process, one case after the other;
* ``executor="processes"``: on a local pool of ``workers`` processes
  (:class:`concurrent.futures.ProcessPoolExecutor`);
* ``executor=client``: on a Dask ``distributed.Client`` -- a ``LocalCluster`` on this machine,
  or the scheduler of a real cluster (the same code; the workers need ukflex installed).

``build`` and ``outputs`` may be lambdas or closures: they are sent to the workers with
``cloudpickle`` (installed with Dask).  A case that raises (a bad parameter, an inconsistent
initial state, a solver failure) becomes a row with ``status = "failed"`` and its message in
``error``; it never aborts the sweep.  Needs the ``sweep`` extra:
``pip install ukflex[sweep]`` (dask[distributed], pandas, tqdm, threadpoolctl).  See
docs/sweeps.md.
"""

from __future__ import annotations

import itertools
import numbers
import os
import pickle
import sys
import time
from typing import Any, Callable, Dict, Iterator, List, Mapping, Optional, Sequence, Tuple, Union

from ..errors import InvalidArgumentError

__all__ = ["sweep", "cases_of", "Cases", "RESERVED_COLUMNS", "MAX_CASES"]

#: Columns :func:`sweep` adds to the case parameters and outputs.
RESERVED_COLUMNS = ("status", "error", "wall_time", "method", "solver_status")

Grid = Union[Mapping[str, Any], Sequence[Mapping[str, Any]]]


def _need(module: str, what: str) -> Any:
    from ..errors import require

    return require(module, what, extra="sweep")


#: Default largest number of cases of one sweep (``max_cases``): a grid beyond it is refused
#: before any case runs (its rows alone would fill memory).
MAX_CASES = 10 ** 6


class Cases:
    """The cases of a grid, generated lazily: ``len(cases)`` is known up front (the product of
    the value lists' lengths, never overflowing) and iterating yields one keyword dict at a time
    (``itertools.product`` order, the last key varying fastest), so a grid is never materialized.

    ``grid`` is a dict of lists (the full factorial; a value that is not a list/tuple/range/array
    is a fixed parameter) or a list of case dicts (taken as they are).  A grid of more than
    ``max_cases`` cases raises :class:`ukflex.InvalidArgumentError` giving its size.
    """

    def __init__(self, grid: Grid, max_cases: int = MAX_CASES):
        from ..arguments import count

        max_cases = count("max_cases", max_cases)
        self._keys: List[str] = []
        self._axes: List[Sequence[Any]] = []
        self._list: Optional[Sequence[Mapping[str, Any]]] = None
        if isinstance(grid, Mapping):
            if not grid:
                raise InvalidArgumentError("grid", "the grid is empty (give a dict of lists or a list of case dicts)")
            size = 1
            for k, v in grid.items():
                if not isinstance(k, str) or not k.isidentifier():
                    raise InvalidArgumentError("grid", f"grid keys must be keyword names, got {k!r}")
                if isinstance(v, (list, tuple, range)) or type(v).__name__ == "ndarray":
                    n = len(v)
                    if not n:
                        raise InvalidArgumentError("grid", f"grid[{k!r}] is an empty list")
                else:
                    v, n = (v,), 1
                self._keys.append(k)
                self._axes.append(v)
                size *= n
            bad = [k for k in self._keys if k in RESERVED_COLUMNS]
        elif isinstance(grid, (list, tuple)):
            if not grid:
                raise InvalidArgumentError("grid", "the list of cases is empty")
            for i, c in enumerate(grid):
                if not isinstance(c, Mapping):
                    raise InvalidArgumentError("grid", f"case {i} must be a dict of keyword arguments, got {type(c).__name__}")
            self._list, size = grid, len(grid)
            bad = sorted({k for c in grid for k in c if k in RESERVED_COLUMNS})
        else:
            raise InvalidArgumentError("grid", f"grid must be a dict of lists or a list of dicts, got {type(grid).__name__}")
        if bad:
            raise InvalidArgumentError("grid", f"case parameter name(s) {bad} clash with the result columns {RESERVED_COLUMNS}")
        if size > max_cases:
            shape = " x ".join(str(len(a)) for a in self._axes) if self._list is None else str(size)
            raise InvalidArgumentError("grid", f"the grid has {size:,} cases ({shape}), more than max_cases = {max_cases:,}; "
                                       "split it into several sweeps or raise max_cases")
        self.size = size

    def __len__(self) -> int:
        return self.size

    def __iter__(self) -> Iterator[Dict[str, Any]]:
        if self._list is not None:
            return (dict(c) for c in self._list)
        return (dict(zip(self._keys, combo)) for combo in itertools.product(*self._axes))


def cases_of(grid: Grid, max_cases: int = MAX_CASES) -> List[Dict[str, Any]]:
    """The list of cases (keyword dicts for ``build``) of a grid (:class:`Cases`, as a list)."""
    return list(Cases(grid, max_cases))


# ----------------------------------------------------------------------------------- one case
def _scalar(name: str, v: Any) -> Any:
    if isinstance(v, (bool, str)) or v is None:
        return v
    if isinstance(v, numbers.Integral):
        return int(v)
    if isinstance(v, numbers.Real):
        return float(v)
    if getattr(v, "shape", None) == () and hasattr(v, "item"):
        return v.item()
    raise TypeError(f"output {name!r} must be a scalar (number, bool or str), got {type(v).__name__}")


def run_case(build: Callable[..., Any], outputs: Callable[[Any], Mapping[str, Any]], case: Dict[str, Any],
             defaults: Dict[str, Any], blas: Optional[int] = 1) -> Dict[str, Any]:
    """One case: ``build(**case)`` -> :func:`ukflex.simulate` -> ``outputs(result)``, as a row dict.

    Never raises for a problem of the case itself: it is reported in ``status``/``error``.
    """
    from ..reference._blas import blas_threads
    from .simulate import simulate

    row: Dict[str, Any] = dict(case)
    tic = time.perf_counter()
    try:
        with blas_threads(blas):
            built = build(**case)
            options = dict(defaults)
            if isinstance(built, tuple):
                if len(built) != 2 or not isinstance(built[1], Mapping):
                    raise TypeError("build must return a Scene/System or (Scene/System, dict of simulate options)")
                built, extra = built
                options.update(extra)
            if "t_end" not in options:
                raise TypeError("no t_end: give sweep(..., t_end=...) or return (scene, {'t_end': ...}) from build")
            t_end = options.pop("t_end")
            res = simulate(built, t_end, **options)
            out = outputs(res)
            if not isinstance(out, Mapping):
                raise TypeError(f"outputs must return a dict of scalars, got {type(out).__name__}")
            for k, v in out.items():
                if k in row or k in RESERVED_COLUMNS:
                    raise ValueError(f"output name {k!r} clashes with a case parameter or a result column")
                row[k] = _scalar(k, v)
        row["status"] = "ok" if res.success else "unfinished"
        row["error"] = "" if res.success else f"solver status {res.status}: {res.message}"
        row["method"] = str(res.method)
        row["solver_status"] = int(res.status)
    except Exception as exc:  # a failed case is a row, never the end of the sweep
        row["status"] = "failed"
        row["error"] = _describe(exc)
        row["method"] = ""
        row["solver_status"] = None
    row["wall_time"] = time.perf_counter() - tic
    return row


_WORKER_FUNCS: Dict[bytes, Tuple[Callable[..., Any], Callable[..., Any]]] = {}


def _run_chunk(payload: bytes, chunk: List[Tuple[int, Dict[str, Any]]], defaults: Dict[str, Any],
               blas: Optional[int]) -> List[Tuple[int, Dict[str, Any]]]:
    """Worker entry (process pool and Dask): ``payload`` is ``cloudpickle.dumps((build, outputs))``,
    unpickled once per worker process; ``chunk`` is a list of ``(case index, case)``."""
    funcs = _WORKER_FUNCS.get(payload)
    if funcs is None:
        _WORKER_FUNCS.clear()
        funcs = _WORKER_FUNCS[payload] = pickle.loads(payload)
    return [(i, run_case(funcs[0], funcs[1], case, defaults, blas)) for i, case in chunk]


def _describe(exc: BaseException) -> str:
    """``Type: first line of the message`` of a case's exception (one whose ``__str__`` fails
    too: a failed case never ends the sweep)."""
    try:
        text = str(exc)
    except Exception:  # noqa: BLE001 - the user's exception class
        text = "(its message cannot be shown: __str__ raised)"
    line = text.splitlines()[0] if text.strip() else ""
    return f"{type(exc).__name__}: {line}" if line else type(exc).__name__


def _failed_row(case: Dict[str, Any], exc: BaseException) -> Dict[str, Any]:
    row = dict(case)
    row.update(status="failed", error=_describe(exc), method="",
               solver_status=None, wall_time=float("nan"))
    return row


# ----------------------------------------------------------------------------------- executors
def _progress_bar(total: int, progress: Optional[bool], label: str) -> Any:
    if progress is None:
        progress = bool(getattr(sys.stderr, "isatty", lambda: False)())
    if not progress:
        return None
    try:
        from tqdm.auto import tqdm
    except ImportError:
        return None
    return tqdm(total=total, desc=label, unit="case", file=sys.stderr)


Chunk = List[Tuple[int, Dict[str, Any]]]


def _chunks(cases: Cases, nworkers: int, chunksize: Optional[int]) -> Iterator[Chunk]:
    """``(case index, case)`` lists of ``chunksize`` cases (default: about 8 tasks per worker, at
    most 64 cases each), drawn from the lazy cases as they are needed."""
    if chunksize is None:
        size = min(64, max(1, -(-len(cases) // (8 * nworkers))))
    else:
        from ..arguments import count

        size = count("chunksize", chunksize)
    it = enumerate(cases)
    while True:
        chunk = list(itertools.islice(it, size))
        if not chunk:
            return
        yield chunk


def _collect(rows: List[Optional[Dict[str, Any]]], chunk: Chunk, fut: Any, bar: Any) -> None:
    """Store a finished task's rows; a lost worker (BrokenProcessPool, KilledWorker) fails its cases."""
    try:
        for i, row in fut.result():
            rows[i] = row
    except Exception as exc:
        for i, case in chunk:
            rows[i] = _failed_row(case, exc)
    if bar is not None:
        bar.update(len(chunk))


#: Tasks in flight per worker: chunks are made and submitted as earlier ones finish, so a large
#: grid never sits in the executor's queue as a whole.
IN_FLIGHT_PER_WORKER = 4


def _is_dask_client(executor: Any) -> bool:
    return type(executor).__module__.split(".")[0] == "distributed" and hasattr(executor, "submit")


def _payload(build: Callable[..., Any], outputs: Callable[..., Any]) -> bytes:
    try:
        import cloudpickle

        return cloudpickle.dumps((build, outputs))
    except ImportError:
        try:
            return pickle.dumps((build, outputs))
        except Exception as exc:
            raise TypeError(f"build/outputs cannot be pickled for worker processes ({exc}); define them at module "
                            "level or install cloudpickle (it comes with dask)") from None


def sweep(
    build: Callable[..., Any],
    grid: Grid,
    outputs: Callable[[Any], Mapping[str, Any]],
    executor: Any = "serial",
    *,
    workers: Optional[int] = None,
    chunksize: Optional[int] = None,
    progress: Optional[bool] = None,
    blas_threads: Optional[int] = 1,
    max_cases: int = MAX_CASES,
    **simulate_options: Any,
) -> Any:
    """Simulate every case of ``grid`` and collect scalar outputs in a DataFrame.

    Parameters
    ----------
    build : callable
        ``build(**case)`` returns what :func:`ukflex.simulate` takes (a Scene, description dict
        or System), or a pair ``(scene, options)`` whose dict of :func:`ukflex.simulate` options
        (``t_end``, ``method``, ``rtol``, ``t_eval``, ...) overrides ``simulate_options``.
    grid : dict of lists, or list of dicts
        Dict: the full factorial of its value lists (:func:`cases_of`); list: the cases.
    outputs : callable
        ``outputs(result)`` -> dict ``{name: scalar}`` from a
        :class:`ukflex.SimulationResult`.
    executor : "serial", "processes" or a dask ``distributed.Client``
        Where the cases run (see the module docs).
    workers : int, optional
        Processes of the ``"processes"`` pool (default ``os.cpu_count()``).
    chunksize : int, optional
        Cases per task sent to a worker (process pool and Dask); default: about 8 tasks per
        worker, at most 64 cases each (fewer round trips for short cases, still balanced).
    progress : bool, optional
        A tqdm progress bar on stderr; default: only when stderr is a terminal (and tqdm is
        installed).
    blas_threads : int or None
        BLAS threads per case (threadpoolctl; default 1, so that workers do not oversubscribe
        the cores); ``None`` leaves BLAS alone.
    max_cases : int
        Largest grid accepted (default :data:`MAX_CASES`, 10**6): a larger one raises
        :class:`ukflex.InvalidArgumentError` giving its size before any case runs.  Cases are
        generated as they are run, never all at once.
    **simulate_options
        Defaults for :func:`ukflex.simulate` (``t_end`` is required here or from ``build``).

    Returns
    -------
    pandas.DataFrame
        One row per case, in case order: the case parameters, the outputs, ``status``
        (``"ok"``; ``"unfinished"``: the integrator stopped early, outputs computed from what it
        returned; ``"failed"``: an exception, no outputs), ``error`` (one line), ``method`` (the
        integrator, useful with ``method="auto"``), ``solver_status`` and ``wall_time`` (seconds
        for build + simulate + outputs in the worker).  ``df.attrs`` holds ``executor``,
        ``workers``, ``wall_time`` (the whole sweep) and ``failed`` (count).
    """
    pd = _need("pandas", "ukflex.sweep")
    if not callable(build) or not callable(outputs):
        raise TypeError("sweep: build and outputs must be callables")
    cases = Cases(grid, max_cases)
    from ..arguments import count

    blas = None if blas_threads is None else count("blas_threads", blas_threads)
    rows: List[Optional[Dict[str, Any]]] = [None] * len(cases)
    tic = time.perf_counter()

    if isinstance(executor, str) and executor == "serial":
        name, nworkers = "serial", 1
        bar = _progress_bar(len(cases), progress, "sweep (serial)")
        for i, case in enumerate(cases):
            rows[i] = run_case(build, outputs, case, simulate_options, blas)
            if bar is not None:
                bar.update(1)
    elif isinstance(executor, str) and executor == "processes":
        from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait

        nworkers = (os.cpu_count() or 1) if workers is None else count("workers", workers)
        name = "processes"
        payload = _payload(build, outputs)
        chunks = _chunks(cases, nworkers, chunksize)
        bar = _progress_bar(len(cases), progress, f"sweep ({nworkers} processes)")
        with ProcessPoolExecutor(max_workers=nworkers) as pool:
            pending: Dict[Any, Chunk] = {}

            def submit(k: int) -> None:
                for chunk in itertools.islice(chunks, k):
                    pending[pool.submit(_run_chunk, payload, chunk, simulate_options, blas)] = chunk

            submit(IN_FLIGHT_PER_WORKER * nworkers)
            while pending:
                done, _ = wait(pending, return_when=FIRST_COMPLETED)
                for fut in done:
                    _collect(rows, pending.pop(fut), fut, bar)
                submit(len(done))
    elif _is_dask_client(executor):
        distributed = _need("distributed", "ukflex.sweep on Dask")
        name = "dask"
        nworkers = len(executor.scheduler_info().get("workers", {}))
        payload = _payload(build, outputs)
        [remote] = executor.scatter([payload], broadcast=True)
        chunks = _chunks(cases, max(nworkers, 1), chunksize)
        bar = _progress_bar(len(cases), progress, "sweep (dask)")
        by_key: Dict[Any, Tuple[Any, Chunk]] = {}

        def submit_dask(k: int) -> List[Any]:
            new = []
            for chunk in itertools.islice(chunks, k):
                f = executor.submit(_run_chunk, remote, chunk, simulate_options, blas, pure=False)
                by_key[f.key] = (f, chunk)
                new.append(f)
            return new

        ac = distributed.as_completed(submit_dask(IN_FLIGHT_PER_WORKER * max(nworkers, 1)))
        try:
            for fut in ac:
                _collect(rows, by_key.pop(fut.key)[1], fut, bar)
                for f in submit_dask(1):
                    ac.add(f)
        finally:
            executor.cancel([f for f, _ in by_key.values() if not f.done()])
    else:
        raise ValueError(f"sweep: executor must be 'serial', 'processes' or a dask distributed Client, got {executor!r}")
    if bar is not None:
        bar.close()

    columns: List[str] = []
    for r in rows:
        for k in r or {}:
            if k not in columns and k not in RESERVED_COLUMNS:
                columns.append(k)
    df = pd.DataFrame(rows, columns=columns + list(RESERVED_COLUMNS))
    df["solver_status"] = df["solver_status"].astype("Int64")  # None for failed cases
    df.attrs.update(executor=name, workers=nworkers, wall_time=time.perf_counter() - tic,
                    failed=int((df["status"] == "failed").sum()))
    return df
