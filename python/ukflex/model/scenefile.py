"""TOML scene files: a scene description plus initial-state, solver and output settings.

A scene file is the description of ``docs/scene-format.md`` written in TOML, one to one
(``dim``, ``gravity``, ``[[bodies]]``, ``[[joints]]``, ``[[drivers]]``, ``[[forces]]``), plus four
optional tables. ``dim = 3`` makes it a spatial scene (:class:`ukflex.SpatialScene`,
docs/spatial.md: ``rigid3`` and ``point3`` bodies, markers as frames, 3-vector gravity);
absent or ``2``: planar. The tables:

``[scene]``
    ``name`` (default: the file name without extension), ``description``.
``[initial]``
    Options of the initial-state correction (:class:`ukflex.System`): ``correct`` (bool),
    ``hold`` (``"elastic"``, ``"none"`` or a list of coordinate names), ``position_tol``,
    ``velocity_tol``, ``max_iterations``, ``t0``.  The initial guess itself is in the bodies'
    state fields (``position``, ``angle``, ``velocity``, ``angular_velocity``, ``elastic``,
    ``elastic_rates``).
``[solver]``
    ``t_end``, ``method``, ``rtol``, ``atol``, ``formulation``, ``samples`` (output points),
    ``max_step``, ``first_step``.  Command-line options override them.
``[output]``
    ``plot`` (list of output expressions, see :mod:`ukflex.results.outputs`), ``animate`` (bool),
    ``deform_scale``, ``fps``, ``frames``.

Example (a rigid pendulum)::

    gravity = [0.0, -9.81]

    [[bodies]]
    name = "rod"
    kind = "rigid"
    mass = 1.0
    inertia = 0.0833
    position = [0.5, 0.0]

    [[joints]]
    kind = "revolute"
    a = { body = "ground", point = [0.0, 0.0] }
    b = { body = "rod", point = [-0.5, 0.0] }

    [solver]
    t_end = 2.0
    method = "DOP853"

Errors (:class:`SceneFileError`, a :class:`ukflex.InvalidSceneError`) name the file, the table
or array entry (with its line when it is written as ``[[bodies]]`` etc.) and the offending key.
"""

from __future__ import annotations

import copy
import difflib
import json
import math
import os
import re
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

from .. import arguments
from ..errors import InvalidArgumentError, InvalidSceneError
from .scene import Scene
from .spatial import SpatialScene

try:  # Python >= 3.11
    import tomllib as _toml
except ImportError:  # pragma: no cover - Python 3.9/3.10
    try:
        import tomli as _toml  # type: ignore[no-redef]
    except ImportError:
        _toml = None  # type: ignore[assignment]

__all__ = ["SceneFile", "SceneFileError", "load", "loads", "dumps", "dump"]

ITEM_ARRAYS = ("bodies", "joints", "drivers", "forces")
TOP_KEYS = ("dim", "gravity") + ITEM_ARRAYS + ("scene", "initial", "solver", "output")
SCENE_KEYS = ("name", "description")
INITIAL_KEYS = ("correct", "hold", "position_tol", "velocity_tol", "max_iterations", "t0")
SOLVER_KEYS = ("t_end", "method", "rtol", "atol", "formulation", "samples", "max_step", "first_step")
OUTPUT_KEYS = ("plot", "animate", "deform_scale", "fps", "frames")
#: Largest count accepted for sizes (samples, frames) in a scene file or on the command line:
#: above it the arrays alone would need gigabytes; refused before anything is allocated.
MAX_COUNT = 10_000_000
#: Largest scene file read (bytes): a scene with 100,000 bodies is ~10 MB of TOML.
MAX_FILE_BYTES = 64 * 1024 * 1024


class SceneFileError(InvalidSceneError):
    """A scene file cannot be read: TOML syntax, unknown or malformed keys, invalid scene."""


@dataclass
class SceneFile:
    """A loaded scene file.

    Attributes
    ----------
    path : str
        Where it came from (``"<string>"`` for :func:`loads`).
    name : str
        ``[scene] name`` or the file name without extension.
    description : str
        ``[scene] description`` (may be empty).
    scene : Scene or SpatialScene
        The validated scene (a :class:`ukflex.SpatialScene` for a file with ``dim = 3``).
    initial : dict
        Keyword arguments for :class:`ukflex.System` (``hold`` already mapped: ``"none"`` -> None).
    solver : dict
        Solver settings present in the file (validated; absent keys are absent).
    output : dict
        Output settings present in the file.
    """

    path: str
    name: str
    description: str
    scene: Union[Scene, SpatialScene]
    initial: Dict[str, Any] = field(default_factory=dict)
    solver: Dict[str, Any] = field(default_factory=dict)
    output: Dict[str, Any] = field(default_factory=dict)

    def build(self):
        """Compile the scene with the file's ``[initial]`` options -> :class:`ukflex.System`."""
        from .system import System

        try:
            return System(self.scene, **self.initial)
        except InvalidSceneError as exc:
            raise SceneFileError(f"{self.path}: {exc}") from None


# ------------------------------------------------------------------------------------- reading
def load(path: Union[str, "os.PathLike[str]"]) -> SceneFile:
    """Read and validate the scene file at ``path``.

    Raises
    ------
    SceneFileError
        Unreadable file, TOML syntax error, unknown or malformed key, invalid scene.
    """
    import stat

    path = os.fspath(path)
    try:
        st = os.stat(path)  # never open a FIFO, a device or a directory: reading them blocks or never ends
        if not stat.S_ISREG(st.st_mode):
            kind = ("a directory" if stat.S_ISDIR(st.st_mode) else "a FIFO" if stat.S_ISFIFO(st.st_mode)
                    else "a device" if stat.S_ISCHR(st.st_mode) or stat.S_ISBLK(st.st_mode) else "a special file")
            raise SceneFileError(f"{path}: not a regular file ({kind}); a scene file is a TOML text file")
        if st.st_size > MAX_FILE_BYTES:
            raise SceneFileError(f"{path}: {st.st_size:,} bytes is too large for a scene file "
                                 f"(at most {MAX_FILE_BYTES:,})")
        with open(path, "rb") as fh:
            raw = fh.read(MAX_FILE_BYTES + 1)
        if len(raw) > MAX_FILE_BYTES:
            raise SceneFileError(f"{path}: too large for a scene file (at most {MAX_FILE_BYTES:,} bytes)")
    except OSError as exc:
        raise SceneFileError(f"{path}: cannot read the scene file ({exc.strerror or exc})") from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise SceneFileError(f"{path}: not UTF-8 text ({exc})") from None
    return loads(text, path=path)


def loads(text: str, path: str = "<string>") -> SceneFile:
    """Parse and validate scene-file text (see :func:`load`)."""
    if _toml is None:  # pragma: no cover
        raise SceneFileError("reading TOML scene files needs Python >= 3.11 or the 'tomli' package")
    try:
        return _loads(text, path)
    except RecursionError:
        raise SceneFileError(f"{path}: arrays or tables nested too deeply for a scene file") from None


def _loads(text: str, path: str) -> SceneFile:
    try:
        data = _toml.loads(text)
    except _toml.TOMLDecodeError as exc:
        raise SceneFileError(f"{path}: TOML syntax error: {exc}") from None

    _check_keys(path, "top level", data, TOP_KEYS)
    meta = _table(path, data, "scene")
    _check_keys(path, "[scene]", meta, SCENE_KEYS)
    if "name" in meta:
        name = meta["name"]
        if not isinstance(name, str) or not re.fullmatch(r"[A-Za-z0-9_+-][A-Za-z0-9_.+-]*", name):
            raise SceneFileError(f"{path}: [scene] name: must be a file-name-safe string (letters, digits, _ . + -, "
                                 f"not starting with a dot), got {name!r}")
    else:  # the file's name, made file-name-safe ("my scene.toml" -> "my_scene")
        stem = os.path.splitext(os.path.basename(path))[0] if path != "<string>" else "scene"
        name = re.sub(r"[^A-Za-z0-9_.+-]", "_", stem).lstrip(".") or "scene"
    desc_text = meta.get("description", "")
    if not isinstance(desc_text, str):
        raise SceneFileError(f"{path}: [scene] description: must be a string, got {desc_text!r}")

    initial = _initial(path, _table(path, data, "initial"))
    solver = _solver(path, _table(path, data, "solver"))
    output = _output(path, _table(path, data, "output"))

    description = {k: copy.deepcopy(data[k]) for k in ("dim", "gravity") + ITEM_ARRAYS if k in data}
    for key in ITEM_ARRAYS:  # "kind" selects the entry's schema: name the entry if it is not a string
        items = description.get(key)
        for i, item in enumerate(items if isinstance(items, list) else []):
            if isinstance(item, dict) and "kind" in item and not isinstance(item["kind"], str):
                raise SceneFileError(f"{path}: {_where((key, i), description, text)}kind: must be a string such as "
                                     f"\"rigid\", got {item['kind']!r}")
            huge = _huge_integer(item)
            if huge:
                raise SceneFileError(f"{path}: {_where((key, i), description, text)}{huge[0]}: integer {huge[1]} is "
                                     "out of range (|n| < 2**53; write a float such as 1e30 if you mean one)")
    if "bodies" not in description:
        raise SceneFileError(f"{path}: no [[bodies]]: a scene needs at least one body")
    scene = _scene(path, text, description)
    return SceneFile(path=path, name=name, description=desc_text, scene=scene, initial=initial,
                     solver=solver, output=output)


def _huge_integer(value: Any, where: str = "") -> Optional[Tuple[str, str]]:
    """``(key path, shortened digits)`` of the first integer beyond 2**53 in ``value``, else None."""
    if isinstance(value, int) and not isinstance(value, bool) and abs(value) >= 2**53:
        digits = str(value)
        return where or "value", digits if len(digits) <= 24 else f"{digits[:10]}...({len(digits)} digits)"
    items = value.items() if isinstance(value, dict) else enumerate(value) if isinstance(value, list) else ()
    for k, v in items:
        found = _huge_integer(v, f"{where}.{k}" if where and isinstance(k, str) else f"{where}[{k}]" if where else str(k))
        if found:
            return found
    return None


def _table(path: str, data: Dict[str, Any], key: str) -> Dict[str, Any]:
    value = data.get(key, {})
    if not isinstance(value, dict):
        raise SceneFileError(f"{path}: {key}: must be a table [{key}], got {type(value).__name__}")
    return value


def _check_keys(path: str, where: str, d: Dict[str, Any], allowed: Sequence[str]) -> None:
    for key in d:
        if key not in allowed:
            close = difflib.get_close_matches(key, allowed, n=1)
            msg = f"{path}: {where}: unknown key {key!r}"
            if close:
                msg += f" (did you mean {close[0]!r}?)"
            msg += f"; allowed: {', '.join(allowed)}"
            if where != "top level" and key in TOP_KEYS:
                msg += f". Top-level keys such as {key!r} must come before the first [table] header"
            raise SceneFileError(msg)


def _number(path: str, where: str, key: str, value: Any, *, positive: bool = False, integer: bool = False,
            minimum: Optional[float] = None) -> Any:
    try:  # an int beyond what a double holds exactly is refused (no OverflowError later)
        if integer or isinstance(value, int) and not isinstance(value, bool):
            arguments.integer(key, value, at_most=2 ** 53)
        else:
            arguments.real(key, value)
        ok = True
    except InvalidArgumentError:
        ok = False
    if ok and positive and value <= 0:
        ok = False
    if ok and minimum is not None and value < minimum:
        ok = False
    if not ok:
        kind = "an integer" if integer else "a number"
        cond = " > 0" if positive else (f" >= {minimum:g}" if minimum is not None else "")
        raise SceneFileError(f"{path}: {where} {key}: must be {kind}{cond}, got {value!r}")
    return value


def _initial(path: str, d: Dict[str, Any]) -> Dict[str, Any]:
    _check_keys(path, "[initial]", d, INITIAL_KEYS)
    out: Dict[str, Any] = {}
    if "correct" in d:
        if not isinstance(d["correct"], bool):
            raise SceneFileError(f"{path}: [initial] correct: must be true or false, got {d['correct']!r}")
        out["correct"] = d["correct"]
    if "hold" in d:
        h = d["hold"]
        if h == "none" or h is False:
            out["hold"] = None
        elif isinstance(h, str):
            out["hold"] = h
        elif isinstance(h, list) and all(isinstance(x, str) for x in h):
            out["hold"] = list(h)
        else:
            raise SceneFileError(f"{path}: [initial] hold: must be \"elastic\", \"none\" or a list of coordinate "
                                 f"names, got {h!r}")
    for key in ("position_tol", "velocity_tol"):
        if key in d:
            out[key] = float(_number(path, "[initial]", key, d[key], positive=True))
    if "max_iterations" in d:
        out["max_iterations"] = _number(path, "[initial]", "max_iterations", d["max_iterations"], integer=True,
                                        minimum=1)
    if "t0" in d:
        out["t0"] = float(_number(path, "[initial]", "t0", d["t0"]))
    return out


def _solver(path: str, d: Dict[str, Any]) -> Dict[str, Any]:
    from ..run.simulate import FORMULATIONS, METHODS, NATIVE_METHODS

    METHODS = ("auto",) + tuple(METHODS) + tuple(NATIVE_METHODS)
    _check_keys(path, "[solver]", d, SOLVER_KEYS)
    out: Dict[str, Any] = {}
    for key in ("t_end", "rtol", "atol", "max_step", "first_step"):
        if key in d:
            out[key] = float(_number(path, "[solver]", key, d[key], positive=True))
    if "samples" in d:
        out["samples"] = _number(path, "[solver]", "samples", d["samples"], integer=True, minimum=2)
        if out["samples"] > MAX_COUNT:
            raise SceneFileError(f"{path}: [solver] samples: {out['samples']} is too large (at most {MAX_COUNT:,})")
    if "method" in d:
        if d["method"] not in METHODS:
            raise SceneFileError(f"{path}: [solver] method: unknown method {d['method']!r}; expected one of "
                                 f"{', '.join(METHODS)}")
        out["method"] = d["method"]
    if "formulation" in d:
        if d["formulation"] not in FORMULATIONS:
            raise SceneFileError(f"{path}: [solver] formulation: unknown formulation {d['formulation']!r}; expected "
                                 f"one of {', '.join(FORMULATIONS)}")
        out["formulation"] = d["formulation"]
    return out


def _output(path: str, d: Dict[str, Any]) -> Dict[str, Any]:
    _check_keys(path, "[output]", d, OUTPUT_KEYS)
    out: Dict[str, Any] = {}
    if "plot" in d:
        p = d["plot"]
        if isinstance(p, str):
            p = [p]
        if not isinstance(p, list) or not all(isinstance(x, str) for x in p):
            raise SceneFileError(f"{path}: [output] plot: must be a list of output expressions, got {d['plot']!r}")
        out["plot"] = list(p)
    if "animate" in d:
        if not isinstance(d["animate"], bool):
            raise SceneFileError(f"{path}: [output] animate: must be true or false, got {d['animate']!r}")
        out["animate"] = d["animate"]
    if "deform_scale" in d:
        out["deform_scale"] = float(_number(path, "[output]", "deform_scale", d["deform_scale"], positive=True))
    if "fps" in d:
        out["fps"] = _number(path, "[output]", "fps", d["fps"], integer=True, minimum=1)
    if "frames" in d:
        out["frames"] = _number(path, "[output]", "frames", d["frames"], integer=True, minimum=2)
        if out["frames"] > MAX_COUNT:
            raise SceneFileError(f"{path}: [output] frames: {out['frames']} is too large (at most {MAX_COUNT:,})")
    return out


def _array_lines(text: str, key: str) -> List[int]:
    """Line numbers (1-based) of the ``[[key]]`` headers in ``text``."""
    pat = re.compile(r"^\s*\[\[\s*" + re.escape(key) + r"\s*\]\]")
    return [i + 1 for i, line in enumerate(text.splitlines()) if pat.match(line)]


def _scene(path: str, text: str, description: Dict[str, Any]) -> Union[Scene, SpatialScene]:
    dim = description.get("dim", 2)
    if isinstance(dim, bool) or dim != 2:  # spatial (dim = 3; any other value: the core names it)
        try:
            return SpatialScene.from_dict(description)
        except InvalidSceneError as exc:
            raise SceneFileError(f"{path}: {exc}") from None
    description.pop("dim", None)
    try:
        scene = Scene.from_dict(description)
        scene.validate()
        return scene
    except InvalidSceneError as exc:
        raise SceneFileError(f"{path}: {_where(getattr(exc, 'entry', None), description, text)}{exc}") from None


def _where(entry: Any, description: Dict[str, Any], text: str) -> str:
    """``[[key]] #k (line L): `` for the array entry ``entry = (key, index)`` the core refused
    (the scene is built in the order bodies, joints, drivers, forces, so a joint that names an
    unknown body is reported at the joint); empty for the top level."""
    if not entry:
        return ""
    key, i = entry
    lines = _array_lines(text, key)
    items = description.get(key) or []
    line = f" (line {lines[i]})" if i < len(lines) and len(lines) == len(items) else ""
    return f"[[{key}]] #{i + 1}{line}: "


# ------------------------------------------------------------------------------------- writing
_BARE_KEY = re.compile(r"^[A-Za-z0-9_-]+$")


def _key(k: str) -> str:
    return k if _BARE_KEY.match(k) else json.dumps(k)


def _value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float) or _is_np_number(v):
        x = float(v)
        if math.isnan(x):
            return "nan"
        if math.isinf(x):
            return "inf" if x > 0 else "-inf"
        r = repr(x)
        return r if any(c in r for c in ".en") else r + ".0"
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{_key(k)} = {_value(x)}" for k, x in v.items() if x is not None) + " }"
    raise TypeError(f"cannot write {type(v).__name__} to TOML: {v!r}")


def _is_np_number(v: Any) -> bool:
    try:
        import numpy as np

        return isinstance(v, (np.floating, np.integer))
    except ImportError:  # pragma: no cover
        return False


def dumps(
    scene: Union[Scene, SpatialScene, Dict[str, Any]],
    *,
    name: Optional[str] = None,
    description: Optional[str] = None,
    initial: Optional[Dict[str, Any]] = None,
    solver: Optional[Dict[str, Any]] = None,
    output: Optional[Dict[str, Any]] = None,
    header: Optional[str] = None,
) -> str:
    """Write a scene (a :class:`Scene` or its description dict) and settings as scene-file text.

    ``loads(dumps(scene)).scene.to_dict() == scene.to_dict()`` (floats are written with
    ``repr``, so they round-trip exactly).
    """
    d = scene.to_dict() if isinstance(scene, (Scene, SpatialScene)) else copy.deepcopy(scene)
    lines: List[str] = []
    if header:
        lines += [f"# {h}" if h else "#" for h in header.splitlines()]
        lines.append("")
    if d.get("dim", 2) != 2:
        lines.append(f"dim = {_value(d['dim'])}")
    if d.get("gravity") is not None:
        lines.append(f"gravity = {_value(d['gravity'])}")
        lines.append("")
    meta = {k: v for k, v in (("name", name), ("description", description)) if v}
    if meta:
        lines.append("[scene]")
        lines += [f"{k} = {_value(v)}" for k, v in meta.items()]
        lines.append("")
    for key in ITEM_ARRAYS:
        for item in d.get(key) or []:
            lines.append(f"[[{key}]]")
            lines += [f"{_key(k)} = {_value(v)}" for k, v in item.items() if v is not None]
            lines.append("")
    for table, values in (("initial", initial), ("solver", solver), ("output", output)):
        if values:
            lines.append(f"[{table}]")
            for k, v in values.items():
                if table == "initial" and k == "hold" and v is None:
                    v = "none"
                if v is not None:
                    lines.append(f"{_key(k)} = {_value(v)}")
            lines.append("")
    return "\n".join(lines).rstrip() + "\n"


def dump(path: Union[str, "os.PathLike[str]"], scene: Union[Scene, SpatialScene, Dict[str, Any]], **kwargs: Any) -> None:
    """Write :func:`dumps` output to ``path``."""
    with open(os.fspath(path), "w", encoding="utf-8") as fh:
        fh.write(dumps(scene, **kwargs))
