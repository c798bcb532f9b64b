"""Limit OpenBLAS to one thread while the reference integrates (small matrices).

The reference works with matrices of size ~10-50. On a loaded machine, multithreaded
OpenBLAS makes a 6x6 solve or a 30x30 eigh 10-100x slower than single-threaded (measured:
``scipy.linalg.lu_solve`` 6x6: 10 us with one thread, 440 us with two on a busy 2-core box).
This context manager finds the OpenBLAS libraries already loaded by NumPy/SciPy
(``/proc/self/maps``) and sets their thread count to 1, restoring it on exit. Best effort:
silently does nothing where that is not possible.
"""
import contextlib
import ctypes

_LIBS = None


def _openblas_libs():
    global _LIBS
    if _LIBS is not None:
        return _LIBS
    libs = []
    try:
        with open("/proc/self/maps") as fh:
            paths = {line.split()[-1] for line in fh if "openblas" in line.lower() and "/" in line}
        for p in sorted(paths):
            try:
                lib = ctypes.CDLL(p)
            except OSError:
                continue
            for sfx in ("scipy_openblas_{}_num_threads64_", "scipy_openblas_{}_num_threads",
                        "openblas_{}_num_threads"):
                try:
                    get = getattr(lib, sfx.format("get"))
                    set_ = getattr(lib, sfx.format("set"))
                except AttributeError:
                    continue
                get.restype = ctypes.c_int
                set_.argtypes = [ctypes.c_int]
                libs.append((get, set_))
                break
    except OSError:
        pass
    _LIBS = libs
    return libs


@contextlib.contextmanager
def single_blas_thread():
    import numpy  # noqa: F401  (make sure the libraries are loaded)
    import scipy.linalg  # noqa: F401
    saved = []
    for get, set_ in _openblas_libs():
        try:
            saved.append((set_, int(get())))
            set_(1)
        except Exception:  # pragma: no cover
            pass
    try:
        yield
    finally:
        for set_, n in saved:
            try:
                set_(n)
            except Exception:  # pragma: no cover
                pass
