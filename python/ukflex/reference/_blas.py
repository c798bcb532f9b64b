"""Limit the threads of the BLAS libraries NumPy/SciPy loaded (threadpoolctl, optional).

The NumPy reference and the Python side of a run work with small matrices (~10-50): on a loaded
machine a multithreaded BLAS makes a 6x6 solve or a 30x30 ``eigh`` 10-100x slower than a single
thread (measured: ``scipy.linalg.lu_solve`` 6x6: 10 us with one thread, 440 us with two on a busy
2-core box), and in a parameter sweep every worker process would otherwise start one BLAS thread
per core.  :func:`blas_threads` uses ``threadpoolctl`` (``pip install ukflex[sweep]`` or
``threadpoolctl`` alone) on every platform; without it the context does nothing.  It lives in the
reference package because the reference may import nothing else of ukflex; :func:`ukflex.sweep`
uses it too.
"""

from __future__ import annotations

import contextlib
from typing import Any, Iterator, Optional

__all__ = ["blas_threads", "have_threadpoolctl", "single_blas_thread"]

_CONTROLLER: Any = None


def have_threadpoolctl() -> bool:
    """Whether ``threadpoolctl`` is importable (so that :func:`blas_threads` acts)."""
    try:
        import threadpoolctl  # noqa: F401
    except ImportError:
        return False
    return True


def _controller() -> Any:
    """One ``ThreadpoolController`` per process (finding the libraries costs ~1 ms)."""
    global _CONTROLLER
    if _CONTROLLER is None:
        import numpy  # noqa: F401  (make sure the libraries are loaded before they are listed)
        import scipy.linalg  # noqa: F401
        from threadpoolctl import ThreadpoolController

        _CONTROLLER = ThreadpoolController()
    return _CONTROLLER


@contextlib.contextmanager
def blas_threads(n: Optional[int] = 1) -> Iterator[None]:
    """Within the context, BLAS libraries use at most ``n`` threads (``None``: leave them alone).

    Restores the previous limits on exit.  Without ``threadpoolctl`` it does nothing.
    """
    if n is None or not have_threadpoolctl():
        yield
        return
    with _controller().limit(limits=int(n), user_api="blas"):
        yield


@contextlib.contextmanager
def single_blas_thread() -> Iterator[None]:
    """BLAS limited to one thread inside the context."""
    with blas_threads(1):
        yield
