"""fleetmap from Python: multi-robot exploration, mapping, map merging and path planning.

Runs explorations from a scenario (a dict, a YAML file, or keyword arguments) and returns their
metrics and per-step arrays; loads and saves maps as numpy arrays (map_server's 0 occupied,
254 free, 205 unknown); merges two maps; plans paths; runs benchmark sweeps; and registers
coordination strategies, path planners, map aligners, localizers and merge methods written in
Python, which scenarios, sweeps, plan_path and merge_maps then use by name like the built-in ones.

    import fleetmap
    run = fleetmap.explore(map="office", robots=2, steps=50, seed=1)
    print(run.metrics["coverage"], run.coverage[-1], run.trajectories[0].shape)
"""
from __future__ import annotations

import csv
import inspect
import io
import json
import math
import os
import sys
from pathlib import Path
from typing import Any, Iterable, Mapping, Optional, Sequence, Union

_here = Path(__file__).resolve().parent
if not (_here / "_built_for.py").is_file():
    # This is the source folder python/fleetmap, found before the built package because python runs
    # inside python/: the built package further along sys.path serves it, or one line says what to do.
    _built = next((d for d in (Path(p or os.getcwd()).resolve() / "fleetmap" for p in sys.path)
                   if (d / "_built_for.py").is_file()), None)
    if _built is None:
        raise ImportError(f"{_here} is fleetmap's source folder, not the package the build makes: set "
                          f"PYTHONPATH=<build folder>/python (e.g. PYTHONPATH=build/python from the repository)")
    __path__[:] = [str(_built)]

try:
    import numpy as np

    from . import _fleetmap
except ImportError as error:  # another python than the one it was built for, or no numpy
    from ._built_for import PYTHON, VERSION
    raise ImportError(f"fleetmap was built for {PYTHON} (Python {VERSION}, with numpy); this is {sys.executable} "
                      f"(Python {sys.version_info.major}.{sys.version_info.minor}): {error}") from error
from ._fleetmap import (  # noqa: F401  (re-exported)
    AssignmentContext,
    Error,
    InputError,
    Map,
    MergeResult,
    PlanResult,
    load_map,
    map_names,
    merge_method_names,
    planner_names,
    strategies,
    localizers,
    map_aligners,
    planners,
    merge_methods,
    strategy_names,
    keep_freed_memory,
)

__all__ = [
    "AssignmentContext", "Error", "InputError", "Map", "MergeResult", "PlanResult", "ExplorationResult",
    "explore", "sweep", "save_results", "load_map", "save_map", "merge_maps", "plan_path", "register_strategy",
    "register_planner", "register_map_aligner", "register_localizer", "register_merge_method",
    "map_names", "strategies", "localizers", "map_aligners", "planners", "merge_methods", "strategy_names", "planner_names", "merge_method_names", "keep_freed_memory",
]

# The built-in maps ship beside the installed package (share/fleetmap/maps); the C++ side looks
# there when the source tree's maps/ is not around and FLEETMAP_MAPS_DIR is not set.
_installed_maps = Path(__file__).resolve().parent.parent.parent.parent.parent / "share" / "fleetmap" / "maps"
if "FLEETMAP_MAPS_DIR" not in os.environ and _installed_maps.is_dir():
    os.environ["FLEETMAP_MAPS_DIR"] = str(_installed_maps)

PathLike = Union[str, os.PathLike]


def _yaml_value(value: Any) -> Any:
    """JSON is YAML: only infinities need spelling as fleetmap's parsers read them ('inf')."""
    if isinstance(value, float) and not math.isfinite(value):
        return "inf" if value > 0 else "-inf"
    if isinstance(value, Mapping):
        return {str(k): _yaml_value(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_yaml_value(v) for v in value]
    if isinstance(value, np.generic):
        return value.item()
    return value


def _spec_text(spec: Union[None, Mapping[str, Any], PathLike], keys: Mapping[str, Any], what: str):
    """(YAML text, source name, base folder) of a dict, a YAML file or keyword arguments."""
    if spec is None:
        data: dict = {}
    elif isinstance(spec, Mapping):
        data = dict(spec)
    else:
        path = Path(spec)
        if keys:
            raise InputError(f"{path}: give either a {what} file or keyword arguments, not both")
        try:
            text = path.read_text()
        except OSError as e:
            raise InputError(f"{path}: cannot read the {what} file ({e.strerror})") from None
        return text, str(path), str(path.parent)
    data.update(keys)
    return json.dumps(_yaml_value(data)), f"{what} (Python)", os.getcwd()


class ExplorationResult:
    """One exploration run.

    Attributes:
        metrics: the dict that `fleetmap explore` writes as metrics.json.
        coverage: float array (steps + 1,): the share of the observable space the team's merged
            map has observed after each step (index 0: the first scan).
        trajectories: per robot, its true poses, float array (steps + 1, 3) of x, y (m), theta (rad).
        estimates: per robot, its estimated poses in the world frame, same shape.
        merged_map: the merged map (a Map) at the end.
        robot_maps: each robot's own map (in its own frame).
        steps: steps taken; finished: every robot ran out of reachable frontiers before the limit.
    """

    def __init__(self, run: "_fleetmap.Run"):
        self._run = run
        self.metrics: dict = json.loads(run.metrics_json())
        self.coverage: np.ndarray = run.coverage
        self.trajectories: list = run.trajectories
        self.estimates: list = run.estimates
        self.steps: int = run.steps
        self.finished: bool = run.finished

    @property
    def merged_map(self) -> Map:
        """The merged map at the end of the run."""
        return self._run.merged_map

    @property
    def robot_maps(self) -> list:
        """Each robot's own map (a Map, in its own frame)."""
        return self._run.robot_maps

    def save(self, folder: PathLike) -> list:
        """Writes the run's files as `fleetmap explore` does (merged.png, robot_<k>.png,
        metrics.json, map.pgm + map.yaml, map.bt, scenario.yaml) into `folder`; returns their paths."""
        return self._run.write_outputs(str(folder))

    def __repr__(self) -> str:
        return (f"<fleetmap.ExplorationResult {self._run.label}: {self.steps} steps, "
                f"coverage {self.coverage[-1]:.3f}>")


def explore(scenario: Union[None, Mapping[str, Any], PathLike] = None, **keys: Any) -> ExplorationResult:
    """Runs one exploration and returns its ExplorationResult.

    `scenario` is a scenario dict (the keys of a scenario YAML file, e.g. {"map": "office",
    "robots": 2, "exploration": {"strategy": "coordinated"}}), the path of a scenario YAML file, or
    None; keyword arguments are further top-level scenario keys (map, robots, steps, seed, ...) and
    override the dict's. `strategy="name"` is short for exploration: {strategy: name}.
    Bad scenarios raise InputError (a ValueError) naming the key.
    """
    if "strategy" in keys:
        strategy = keys.pop("strategy")
        exploration = dict((scenario or {}).get("exploration", {}) if isinstance(scenario, Mapping) else {})
        exploration.update(keys.pop("exploration", {}))
        exploration["strategy"] = strategy
        keys["exploration"] = exploration
    text, source, base = _spec_text(scenario, keys, "scenario")
    return ExplorationResult(_fleetmap._explore(text, source, base))


_TEXT_COLUMNS = {"map", "strategy", "variant", "localization", "merging", "settings"}


def _number(text: str) -> Any:
    if text == "":
        return None
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return {"true": True, "false": False}.get(text, text)


def sweep(spec: Union[None, Mapping[str, Any], PathLike] = None, jobs: int = 1, out: Optional[PathLike] = None,
          **keys: Any) -> list:
    """Runs a benchmark sweep (every map x strategy x team size x seed) and returns its rows.

    `spec` is a sweep dict or sweep YAML file (keys as `fleetmap bench --sweep`: maps, strategies,
    robots, seeds, steps, comm_range, vary, ...); keyword arguments add keys. Returns one dict per
    run with the columns of bench's results.csv (numbers as int/float, empty cells as None), in the
    sweep's order. `jobs` runs that many simulations at once. With `out`, also writes the folder
    `fleetmap bench --out` writes (results.csv, summary.csv, summary.md, the plots, report.html,
    sweep.yaml, scenario.yaml), which `fleetmap bench --compare A B out` and `--combine out ...`
    read; the folder must be new, empty, or written before by a sweep (its files are replaced).
    """
    text, source, base = _spec_text(spec, keys, "sweep")
    lines = _fleetmap._sweep(text, source, base, int(jobs), "" if out is None else str(out))
    rows = csv.DictReader(io.StringIO("\n".join(lines) + "\n"))
    return [{k: v if k in _TEXT_COLUMNS else _number(v) for k, v in row.items()} for row in rows]


def _cell_text(value: Any) -> str:
    """A value of a sweep row as results.csv spells it before bench formats it."""
    if isinstance(value, np.generic):
        value = value.item()
    if value is None:
        return ""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float) and math.isinf(value):
        return "inf" if value > 0 else "-inf"
    return str(value)


def save_results(rows: Iterable[Mapping[str, Any]], path: PathLike) -> None:
    """Writes rows of sweep() (any of them, of one sweep or several) as results.csv, in exactly the
    columns and formats `fleetmap bench` writes, so that `fleetmap bench --compare A B FOLDER` and
    `--combine FOLDER ... --out DIR` (summary, plots, report.html) read them. A row without a
    column, or with a value bench would not read, raises InputError naming the row and column."""
    columns = _fleetmap._results_header().split(",")
    lines = []
    for i, row in enumerate(rows):
        missing = [c for c in columns if c not in row]
        if missing:
            raise InputError(f"save_results: rows[{i}]: no column '{missing[0]}' (a row of fleetmap.sweep() has "
                             f"every column of results.csv)")
        lines.append(",".join(_cell_text(row[c]) for c in columns))
    _fleetmap._write_results(lines, str(path))


def save_map(map: Map, path: PathLike) -> None:
    """Saves a map: a .yaml path writes map_server's YAML and a .pgm beside it; .png/.pgm the image."""
    map.save(str(path))


def merge_maps(a: Map, b: Map, method: str = "auto", min_confidence: float = 0.5, seed: int = 1,
               params: Mapping[str, Mapping[str, Any]] | None = None) -> MergeResult:
    """Aligns map b to map a as `fleetmap merge a b` does (maps of two resolutions too).

    The result's `transform` (tx, ty, theta) takes b's map frame into a's, in metres and degrees: a
    point p of b (metres, in the frame b's origin defines; a bare image's lower-left corner is
    (0, 0)) lies at R(theta) p + (tx, ty) in a's, R(theta) = [[cos, -sin], [sin, cos]] - the
    numbers `fleetmap merge` prints and writes as tx_m, ty_m, theta_deg. `pixel_transform` is the
    same in pixels (tx_px, ty_px, theta_px_deg, with `scale`). `confidence` is in [0, 1] and
    `merged` says whether it reached `min_confidence`. `covariance` (3 x 3, metres, metres,
    radians) says how sure `transform` is in which direction, `std` gives its standard deviations
    (m, m, deg) and `uncertain_direction` the largest and smallest (m) where the maps overlap with
    the largest's direction (deg). `map` is the fused map (in a's frame and
    resolution, what `fleetmap merge a b --out merged.yaml` writes), for plan_path; None when not
    merged. `params` gives merge methods their own parameters by method name (merge_methods()
    lists them), e.g. {"features": {"ratio": 0.7}}: for `method` itself, or under "auto" for any
    method it runs; checked as `fleetmap merge --set features.ratio=0.7` checks them."""
    for name, value in (("a", a), ("b", b)):
        if not isinstance(value, Map):
            raise InputError(f"merge_maps: {name} must be a fleetmap.Map (load_map, Map.from_image), "
                             f"got {type(value).__name__}")
    settings = []
    for merge_method, values in (params or {}).items():
        if not isinstance(values, Mapping):
            raise InputError(f"merge_maps: params['{merge_method}'] must be a dict of that method's parameters, "
                             f"got {type(values).__name__}")
        settings.append((str(merge_method), [(str(k), _setting_text(v)) for k, v in values.items()]))
    return _fleetmap._merge_maps(a, b, method, min_confidence, seed, settings)


def _setting_text(value: Any) -> str:
    """A parameter's value as a scenario file writes it."""
    return ("true" if value else "false") if isinstance(value, bool) else str(value)


def plan_path(map: Map, start: Sequence[float], goal: Sequence[float], planner: str = "astar",
              robot_radius: float = 0.2, time_budget: float = 1.0, seed: int = 1,
              params: Mapping[str, Any] | None = None) -> PlanResult:
    """Plans a path for a round robot from `start` to `goal` (x, y in metres) on `map`, unknown
    cells counting as obstacles. `planner` is one of planner_names(); `params` its own parameters
    (planners() lists them, e.g. {"look_ahead": 1.0} for "reactive"), checked as `fleetmap plan
    --set planner.KEY=VALUE` checks them. The result's `path` is an (N, 2) array of waypoints;
    `status` says why there is none."""
    if not isinstance(map, Map):
        got = "None (a merge_maps result that did not merge has no map)" if map is None else type(map).__name__
        raise InputError(f"plan_path: map must be a fleetmap.Map, got {got}")
    settings = [(str(k), _setting_text(v)) for k, v in (params or {}).items()]
    return _fleetmap._plan_path(map, (float(start[0]), float(start[1])), (float(goal[0]), float(goal[1])),
                                planner, float(robot_radius), float(time_budget), int(seed), settings)


def _takes_context(name: str, cls: Any) -> bool:
    """Whether cls's assign takes the optional context after its four arrays."""
    assign = cls.assign
    try:
        parameters = list(inspect.signature(assign).parameters.values())
    except (TypeError, ValueError):  # no signature to read: the four arrays only
        return False
    if any(p.kind == p.VAR_POSITIONAL for p in parameters):
        return True
    positional = [p for p in parameters if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)]
    # A plain method read from the class still lists self.
    if inspect.isfunction(assign) and not isinstance(inspect.getattr_static(cls, "assign"), staticmethod):
        positional = positional[1:]
    required = [p for p in positional if p.default is p.empty]
    if len(required) > 5 or len(positional) < 4:
        raise InputError(f"register_strategy '{name}': assign must take (poses, targets, costs, claimed"
                         f"[, context]); it takes {len(positional)} arguments besides self")
    return len(positional) >= 5


def _param_declarations(name: str, params, what: str = "register_strategy") -> list:
    """The `params` of register_strategy (or of `what`, another register_ function) as the tuples the
    C++ side declares them from."""
    out = []
    for key, spec in (params or {}).items():
        if not isinstance(spec, Mapping):
            spec = {"default": spec}
        unknown = set(spec) - {"default", "unit", "min", "max", "choices", "doc"}
        if unknown or "default" not in spec:
            raise InputError(f"{what} '{name}': parameter '{key}' needs a default and takes only "
                             f"default, unit, min, max, choices, doc (got {sorted(spec)})")
        default = spec["default"]
        if isinstance(default, bool):
            kind, text = "flag", "true" if default else "false"
        elif isinstance(default, (int, float)):
            kind, text = "number", repr(float(default)) if isinstance(default, float) else str(default)
        elif isinstance(default, str):
            kind, text = "text", default
        else:
            raise InputError(f"{what} '{name}': parameter '{key}': the default must be a number, "
                             f"True/False or a word, not {type(default).__name__}")
        lo = float(spec.get("min", -math.inf))
        hi = float(spec.get("max", math.inf))
        out.append((str(key), kind, text, str(spec.get("unit", "")), lo, hi, False,
                    [str(c) for c in spec.get("choices", [])], str(spec.get("doc", ""))))
    return out


def register_strategy(name: str, cls: type, help: str = "", joint: bool = True, params: Mapping | None = None) -> None:
    """Registers a coordination strategy written in Python under `name`.

    `cls` is a class (or any callable) that makes one strategy object per run. Its method
        assign(poses, targets, costs, claimed[, context]) -> sequence of ints
    gets the robots to assign now as an (R, 3) array of poses (x, y in metres, heading in radians
    in (-pi, pi], counter-clockwise from +x, as the robot believes it), the frontier targets as a
    (T, 4) array (goal x, goal y, frontier cells in the piece, frontier region index), the wave
    costs (R, T) in metres (inf: unreachable) and the goals other robots already drive to (K, 2);
    it returns, per robot, a target index or -1 for none. When assign takes a fifth argument it
    also gets an AssignmentContext: each robot's team index and the team size, the sensor range,
    the strategy's parameters (context.params, a dict), and, computed when called, the wave costs
    between the targets (target_costs(), T x T) and the unknown area behind each target
    (target_gains(), square metres) - what the built-in C++ strategies use. The context is valid
    only during the call. With `joint`, every robot that can talk is reassigned together;
    otherwise only the robot that needs a target. Scenarios and sweeps then use `name` like a
    built-in strategy.

    `params` declares the strategy's own settings, each by name: a default (a number, True/False or
    a word), or a dict {default, unit, min, max, choices, doc}. A scenario sets them with
    exploration: {strategy: {name: NAME, KEY: VALUE}}, the command line with --set strategy.KEY=VALUE,
    a sweep varies them with --vary strategy.KEY=V1,V2; each is checked against its declaration.
    """
    if not hasattr(cls, "assign"):
        raise InputError(f"register_strategy '{name}': the class has no assign method")
    _fleetmap._register_strategy(name, cls, help, bool(joint), _takes_context(name, cls),
                                 _param_declarations(name, params))


def _check_method(what: str, name: str, cls: Any, method: str, arguments: Sequence[str],
                  optional: bool = False) -> bool:
    """Whether cls has `method` taking `arguments` besides self; raises InputError naming the plug-in
    when it lacks a required one or takes other arguments."""
    if getattr(cls, method, None) is None:
        if optional:
            return False
        raise InputError(f"{what} '{name}': the class has no {method} method")
    function = getattr(cls, method)
    try:
        parameters = list(inspect.signature(function).parameters.values())
    except (TypeError, ValueError):  # no signature to read: trusted
        return True
    if any(p.kind == p.VAR_POSITIONAL for p in parameters):
        return True
    positional = [p for p in parameters if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)]
    if inspect.isfunction(function) and not isinstance(inspect.getattr_static(cls, method), staticmethod):
        positional = positional[1:]  # a plain method read from the class still lists self
    required = [p for p in positional if p.default is p.empty]
    if len(required) > len(arguments) or len(positional) < len(arguments):
        raise InputError(f"{what} '{name}': {method} must take ({', '.join(arguments)}); it takes "
                         f"{len(positional)} arguments besides self")
    return True


def _check_made_as(what: str, name: str, cls: Any, arguments: Sequence[str]) -> None:
    """Raises InputError naming the plug-in when cls cannot be called with `arguments`."""
    try:
        signature = inspect.signature(cls)
    except (TypeError, ValueError):  # no signature to read: trusted
        return
    try:
        signature.bind(*arguments)
    except TypeError:
        raise InputError(f"{what} '{name}': the class is made as cls({', '.join(arguments)}), which its "
                         f"signature {signature} does not take") from None


def register_planner(name: str, cls: type, help: str = "", params: Mapping | None = None,
                     complete: bool = False) -> None:
    """Registers a path planner written in Python under `name`.

    `cls` is a class (or any callable) called without arguments to make one planner object per
    plan_path call (and per run of a scenario with exploration: {path_planner: NAME}). Its method
        search(free, resolution, origin, start, goal, params) -> list of (x, y), or None
    gets `free`, a bool (height, width) array of the map's cells, top row first as Map.image,
    True where the robot's centre may be (a known free cell farther than the robot radius from
    every obstacle and unknown cell); `resolution`, metres per cell; `origin`, the pose
    (x, y, theta) of the map's lower-left corner, so that with theta 0 the centre of free[row, col]
    is (origin x + (col + 0.5) * resolution, origin y + (height - row - 0.5) * resolution); `start`
    and `goal`, (x, y) in metres, both valid and connected (plan_path answers the other cases
    itself); and `params`, a dict of the declared parameters' values. It returns the waypoints in
    metres from the start to the goal, or None when it finds no path (status 'no path within
    budget'). The path is checked as every planner's must be: its ends must lie within half a
    cell's diagonal of the start and the goal (the centres of their cells do; the ends are then
    replaced by them) and every straight segment must stay in the free space; a path that does not
    raises fleetmap.Error naming the planner and the segment. An exception raised in search becomes
    a fleetmap.Error naming the planner. plan_path's time_budget does not stop a Python search: it
    runs until it returns.

    `help` is the one line planners() shows. `params` declares the planner's own settings as
    register_strategy's do, by name: a default (a number, True/False or a word), or a dict
    {default, unit, min, max, choices, doc}; plan_path(..., params={KEY: VALUE}) and a scenario's
    exploration: {path_planner: {name: NAME, KEY: VALUE}} set them, checked against the
    declaration. `complete`: whether it finds a path whenever one
    exists (the test harnesses hold complete planners to it).
    """
    _check_made_as("register_planner", name, cls, [])
    _check_method("register_planner", name, cls, "search", ["free", "resolution", "origin", "start", "goal", "params"])
    _fleetmap._register_planner(name, cls, help, bool(complete), _param_declarations(name, params, "register_planner"))


def register_map_aligner(name: str, cls: type, help: str = "", params: Mapping | None = None) -> None:
    """Registers a map aligner written in Python under `name`: a way two robots in different map
    frames find the transform between them, so that one takes the other's map (scenario
    merging: NAME, or merging: {mode: NAME, KEY: VALUE}).

    `cls` is a class (or any callable) called without arguments to make one aligner object per
    run. Its method
        align(receiver_map, sender_map, receiver_pose, sender_pose, params)
            -> None or (tx, ty, theta, confidence)
    gets the two robots' maps as fleetmap.Map copies (`.image` the uint8 array, 254 free, 0
    occupied, 205 unknown, top row first; `.resolution`; `.origin`), each in its robot's own map
    frame; the robots' estimated poses (x, y, theta) in those frames; and `params`, a dict of the
    declared parameters' values. It returns None when it found no alignment (recorded as a refused
    merge), or the transform that takes a point of the sender's frame into the receiver's,
    p_receiver = R(theta) p_sender + (tx, ty), in metres and radians, with a confidence in [0, 1]:
    the sender's robots then take the receiver's frame. merge_maps(receiver_map, sender_map) gives
    such a transform (in degrees). The sender's map counts as sent with every attempt, and attempts
    of one pair are spaced by the scenario's merging.attempt_every steps. An exception raised in
    align becomes a fleetmap.Error naming the aligner.

    `help` is the one line map_aligners() shows. `params` declares its settings as
    register_strategy's do; a scenario sets them with merging: {mode: NAME, KEY: VALUE} (what
    --set merging.KEY=VALUE does on the command line), each checked against its declaration.
    """
    _check_made_as("register_map_aligner", name, cls, [])
    _check_method("register_map_aligner", name, cls, "align",
                  ["receiver_map", "sender_map", "receiver_pose", "sender_pose", "params"])
    _fleetmap._register_map_aligner(name, cls, help, _param_declarations(name, params, "register_map_aligner"))


def register_localizer(name: str, cls: type, help: str = "", params: Mapping | None = None) -> None:
    """Registers a localizer written in Python under `name` (scenario localization: NAME, or
    localization: {name: NAME, KEY: VALUE}).

    `cls` is called as cls(initial_pose, params, seed) to make one localizer per robot:
    `initial_pose` (x, y, theta) is where the robot starts in its map frame (metres, radians),
    `params` a dict of the declared parameters' values, `seed` an int for the robot's own random
    numbers. Each step the simulator calls
        predict(dx, dy, dtheta): the step's odometry as a motion in the robot's frame before it
            (dx forward, dy to the left, metres; dtheta counter-clockwise, radians), which differs
            from the true motion by the scenario's noise;
        update_scan(ranges, angles, max_range), only when the class has it: the range scan as two
            float arrays of one value per beam (metres, inf where no return came within
            max_range; radians in the robot's frame);
        pose() -> (x, y, theta): the estimate in the robot's map frame;
        covariance() -> 3 x 3 array, only when the class has it: the estimate's covariance in x, y,
            theta (taken as zero without it);
        change_frame(tx, ty, theta), only when the class has it: after a merge, the estimate
            re-expressed in the new frame, x_new = R(theta) x_old + (tx, ty), heading + theta; a
            robot whose localizer lacks it cannot take a teammate's map frame (an error).
    An exception raised in any of them becomes a fleetmap.Error naming the localizer.

    `help` is the one line localizers() shows. `params` declares its settings as
    register_strategy's do; a scenario sets them with localization: {name: NAME, KEY: VALUE} (what
    --set localization.KEY=VALUE does on the command line), each checked against its declaration.
    """
    _check_made_as("register_localizer", name, cls, ["initial_pose", "params", "seed"])
    _check_method("register_localizer", name, cls, "predict", ["dx", "dy", "dtheta"])
    _check_method("register_localizer", name, cls, "pose", [])
    _check_method("register_localizer", name, cls, "update_scan", ["ranges", "angles", "max_range"], optional=True)
    _check_method("register_localizer", name, cls, "covariance", [], optional=True)
    _check_method("register_localizer", name, cls, "change_frame", ["tx", "ty", "theta"], optional=True)
    _fleetmap._register_localizer(name, cls, help, _param_declarations(name, params, "register_localizer"))


def register_merge_method(name: str, cls: type, help: str = "", params: Mapping | None = None) -> None:
    """Registers a merge method written in Python under `name`: merge_maps(a, b, method=NAME) and
    `auto` (which runs every method) use it, and so do robots that merge by overlap search
    (scenario merging: {mode: overlap, method: NAME}).

    `cls` is called as cls(params) when a merge starts, `params` a dict of the declared
    parameters' values. Its method
        propose(a, b) -> list of (tx, ty, theta) or (tx, ty, theta, score)
    gets the two maps as the merge sees them, fleetmap.Map copies (`.image` uint8, top row first,
    254 free, 0 occupied, 205 unknown; `.resolution`, the same for both; `.origin`), perhaps cut to
    the box of their known cells: each map's `origin` is then where that box's lower-left corner
    lies in the frame of the map given to merge_maps, so that the centre of image[row, col] lies at
    origin (x, y) + R(origin theta) ((col + 0.5) * resolution, (height - row - 0.5) * resolution).
    Each candidate is a transform in METRES and RADIANS between those frames, as merge_maps'
    `transform` (there in degrees): a point p of b lies at R(theta) p + (tx, ty) in a. `score`
    ranks the method's own candidates (higher is better); without it the list's order does, first
    best. The common pipeline then treats them as a built-in method's: it refines each against
    the maps' walls at full resolution (that corrects a candidate a few cells off, not more),
    scores it and decides: `confidence`, refusal, `method` NAME when one of them wins. An empty
    list proposes nothing. An exception raised in propose, or an answer of another shape, becomes
    a fleetmap.Error naming the method. Merges may run on other threads (sweeps with jobs > 1);
    each call takes the interpreter's lock.

    `help` is the one line merge_methods() shows. `params` declares its settings as
    register_strategy's do; merge_maps(..., params={NAME: {KEY: VALUE}}) sets them, each checked
    against its declaration (robots merging by overlap search use the declared defaults).
    """
    _check_made_as("register_merge_method", name, cls, ["params"])
    _check_method("register_merge_method", name, cls, "propose", ["a", "b"])
    _fleetmap._register_merge_method(name, cls, help, _param_declarations(name, params, "register_merge_method"))
