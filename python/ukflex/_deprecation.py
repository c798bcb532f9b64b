"""Old names kept for one release: renamed keyword arguments and moved modules.

Every use issues a :class:`DeprecationWarning` that names the new spelling.
"""

from __future__ import annotations

import functools
import importlib
import warnings
from typing import Any, Callable, Dict, Mapping, Optional, Tuple


def renamed_parameters(**old_to_new: str) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """Decorator: accept the old keyword names ``old_to_new`` and pass them on under the new ones.

    ``@renamed_parameters(beam="theory")`` makes ``f(beam="x")`` call ``f(theory="x")`` with a
    warning; giving both names is a ``TypeError``.
    """

    def decorate(fn: Callable[..., Any]) -> Callable[..., Any]:
        @functools.wraps(fn)
        def wrapper(*args: Any, **kwargs: Any) -> Any:
            for old, new in old_to_new.items():
                if old in kwargs:
                    if new in kwargs:
                        raise TypeError(f"{fn.__name__}() got both {old}= (deprecated) and {new}=")
                    warnings.warn(f"{fn.__name__}({old}=...) is deprecated and will be removed; use {new}=...",
                                  DeprecationWarning, stacklevel=2)
                    kwargs[new] = kwargs.pop(old)
            return fn(*args, **kwargs)

        wrapper.__renamed_parameters__ = dict(old_to_new)  # type: ignore[attr-defined]
        return wrapper

    return decorate


def moved_module(old: str, new: str,
                 renamed: Optional[Mapping[str, Mapping[str, str]]] = None) -> Tuple[Callable[[str], Any], Callable[[], Any]]:
    """For the module ``old`` that moved to ``new``: warn (once, at import) and return the module
    ``__getattr__`` and ``__dir__`` that forward every name to ``new``.

    ``renamed`` maps a function name to the keyword renames its old spelling still accepts
    (``{"stiff": {"beam": "theory"}}``).
    """
    warnings.warn(f"{old} moved to {new}; the old module path will be removed", DeprecationWarning, stacklevel=3)
    module = importlib.import_module(new)
    wrapped: Dict[str, Any] = {name: renamed_parameters(**kw)(getattr(module, name))
                               for name, kw in (renamed or {}).items()}

    def __getattr__(name: str) -> Any:
        return wrapped[name] if name in wrapped else getattr(module, name)

    def __dir__() -> Any:
        return dir(module)

    return __getattr__, __dir__
