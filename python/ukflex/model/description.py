"""The scene description: plain JSON-compatible data (``docs/scene-format.md``), validated by the core.

This module only *coerces* Python values into the description format (NumPy scalars and arrays
to numbers and lists, markers, sections and motions to their dicts) and adds context to errors.
Every rule -- what is valid, the defaults, row and coordinate counts, derived values such as a
spring's default rest length -- belongs to the Rust core: each item is handed to
``ukflex._core.SceneChecker`` as it is added, which validates it in the context of the items
before it (the same code that builds the model) and returns the item with its defaults filled in.
"""

from __future__ import annotations

import json
import math
import numbers
import reprlib
from typing import Any, Dict, List, Mapping, Optional, Tuple

from ..errors import InvalidSceneError, core

__all__ = ["SECTIONS", "Checker", "normalize", "plain"]

#: The four item lists of a description, in the order the core builds them.
SECTIONS = ("bodies", "joints", "drivers", "forces")
_WORD = {"bodies": "body", "joints": "joint", "drivers": "driver", "forces": "force"}


#: Deepest nesting of lists and dicts in a description (a flexible body's fourth-order tensor
#: ``k4`` sits 6 deep; the core's JSON reader stops at 128).
MAX_NESTING = 64


def plain(item: str, path: str, value: Any, _depth: int = 0) -> Any:
    """``value`` as JSON-compatible data (dicts, lists, str, int, float, bool, None).

    Objects with ``to_dict()`` (markers, sections, motions) become their dicts.  A number JSON
    cannot carry (NaN, infinity) is refused here, naming ``item`` and ``path``; so is nesting
    deeper than :data:`MAX_NESTING` (it would exhaust the interpreter's recursion).
    """
    if _depth > MAX_NESTING:
        raise InvalidSceneError(f"{item}: {path or 'value'}: lists or dicts nested deeper than {MAX_NESTING} levels")
    if hasattr(value, "to_dict") and callable(value.to_dict):
        return plain(item, path, value.to_dict(), _depth + 1)
    if getattr(value, "_is_body_handle", False):
        raise InvalidSceneError(
            f"{item}{' ' + path if path else ''}: expected a marker (e.g. {value.name}.point(x, y) or .at(xi)), "
            f"got the body handle {value!r}"
        )
    if value is None or isinstance(value, (bool, str)):
        return value
    if isinstance(value, numbers.Integral):
        return int(value)
    if isinstance(value, numbers.Real):
        x = float(value)
        if not math.isfinite(x):
            raise InvalidSceneError(f"{item}: {path or 'value'} must be finite, got {x!r}")
        return x
    if isinstance(value, Mapping):
        return {str(k): plain(item, f"{path}.{k}" if path else str(k), v, _depth + 1) for k, v in value.items()}
    if hasattr(value, "tolist") and not isinstance(value, (bytes, bytearray)):
        value = value.tolist()
    if isinstance(value, (list, tuple)):
        return [plain(item, f"{path}[{i}]", v, _depth + 1) for i, v in enumerate(value)]
    raise InvalidSceneError(f"{item}: {path or 'value'}: cannot be written into a scene description: {reprlib.repr(value)}")


class Checker:
    """A scene under construction, validated item by item by the core.

    ``items[section]`` holds the normalized items (defaults filled in by the core) and
    ``info[section]`` what the core derived from each (coordinate counts, row counts, names).
    """

    def __init__(self, gravity: Any = None):
        g = None if gravity is None else plain("scene", "gravity", gravity)
        self._core = core.SceneChecker(None if g is None else json.dumps(g))
        self.gravity: Optional[List[float]] = g
        self.items: Dict[str, List[Dict[str, Any]]] = {s: [] for s in SECTIONS}
        self.info: Dict[str, List[Dict[str, Any]]] = {s: [] for s in SECTIONS}

    def label(self, section: str, item: Mapping[str, Any]) -> str:
        """How errors name ``item`` if it were added to ``section`` now."""
        kind, name = item.get("kind"), item.get("name")
        kind = kind if isinstance(kind, str) else reprlib.repr(kind)
        return core.item_name(section, kind, name if isinstance(name, str) else None, len(self.items[section]))

    def add(self, section: str, item: Mapping[str, Any]) -> Dict[str, Any]:
        """Validate ``item`` and append it to ``section``; returns what the core derived from it.

        Raises
        ------
        InvalidSceneError
            Naming the item; nothing is added.
        """
        d = plain(self.label(section, item), "", dict(item))
        if section == "drivers" and isinstance(d.get("motion"), str):  # a motion written as an expression of t
            d["motion"] = {"kind": "expression", "expression": d["motion"]}
        info = dict(getattr(self._core, "add_" + _WORD[section])(json.dumps(d, allow_nan=False)))
        self.items[section].append(json.loads(info.pop("item")))
        self.info[section].append(info)
        return info

    def finish(self) -> None:
        """Whole-scene checks (at least one body)."""
        self._core.finish()

    def to_dict(self) -> Dict[str, Any]:
        d: Dict[str, Any] = {}
        if self.gravity is not None:
            d["gravity"] = list(self.gravity)
        for s in SECTIONS:
            d[s] = json.loads(json.dumps(self.items[s]))  # a deep copy of plain data
        return d


def check_top_level(description: Any) -> None:
    """The top level of a description (its keys and list types), by the core."""
    if not isinstance(description, Mapping):
        raise InvalidSceneError(f"scene: expected a dict, got {type(description).__name__}")
    top = {k: ([] if k in SECTIONS and isinstance(v, list) else v) for k, v in description.items()}
    core.SceneChecker.check_top_level(json.dumps(plain("scene", "", top)))


def normalize(description: Mapping[str, Any]) -> Tuple[Checker, Dict[str, Any]]:
    """Validate a whole description item by item; returns the checker and the normalized dict.

    An error about an item carries ``exc.entry = (section, index)`` (0-based) so that callers
    (scene files) can say where it stands.
    """
    if isinstance(description, Mapping) and description.get("dim", 2) != 2:
        from .spatial import normalize_spatial  # spatial scenes: validated whole by the core
        return normalize_spatial(dict(description))
    check_top_level(description)
    checker = Checker(description.get("gravity"))
    for section in SECTIONS:
        for index, item in enumerate(description.get(section) or []):
            try:
                if not isinstance(item, Mapping):
                    raise InvalidSceneError(f"scene: every entry of {section} must be a dict, got {reprlib.repr(item)}")
                checker.add(section, item)
            except InvalidSceneError as exc:
                exc.entry = (section, index)
                raise
    return checker, checker.to_dict()
