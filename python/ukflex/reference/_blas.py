"""Limit BLAS to one thread while the reference integrates (small matrices).

See :mod:`ukflex._threads` (threadpoolctl; without it the context does nothing).
"""
from __future__ import annotations

import contextlib
from typing import Iterator

from .._threads import blas_threads


@contextlib.contextmanager
def single_blas_thread() -> Iterator[None]:
    """BLAS limited to one thread inside the context."""
    with blas_threads(1):
        yield
