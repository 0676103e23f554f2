# Type hints of the package `fleetmap` (the Python half in __init__.py, the C++ half in _fleetmap).
import os
from typing import Any, Iterable, Mapping, Optional, Protocol, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

PathLike = Union[str, os.PathLike]

class InputError(ValueError):
    """Bad input: a scenario key, a map file, a name; the message names it."""

class Error(RuntimeError):
    """Any other failure inside fleetmap."""

class Map:
    """An occupancy grid map (cells Free, Occupied or Unknown)."""
    @staticmethod
    def from_image(image: npt.ArrayLike, resolution: float = 0.05,
                   origin: Tuple[float, float, float] = (0.0, 0.0, 0.0)) -> "Map":
        """A map from a uint8 (rows, columns) image, top row first, read with map_server's rules:
        dark (0) occupied, light (254) free, mid-grey (205) unknown. `origin`: the pose (x, y, theta)
        of the lower-left corner in metres."""
    @property
    def image(self) -> npt.NDArray[np.uint8]:
        """The map_saver image: uint8 (height, width), top row first, 254 free, 0 occupied, 205 unknown."""
    @property
    def width(self) -> int: ...
    @property
    def height(self) -> int: ...
    @property
    def resolution(self) -> float:
        """Metres per cell."""
    @property
    def origin(self) -> Tuple[float, float, float]:
        """The pose (x, y, theta) of the lower-left corner."""
    @property
    def free_cells(self) -> int: ...
    @property
    def occupied_cells(self) -> int: ...
    def save(self, path: PathLike) -> None:
        """.yaml: map_server YAML plus a .pgm beside it; .png / .pgm: the image alone."""
    def resampled(self, resolution: float) -> "Map":
        """The map seen through cells of `resolution` metres (same origin and extent): a cell is
        occupied when any old cell inside it is, free when half of them are. InputError over 64 million
        cells."""

class MergeResult:
    """Map b aligned to map a, as `fleetmap merge a b` aligns them."""
    @property
    def merged(self) -> bool: ...
    @property
    def confidence(self) -> float: ...
    @property
    def acceptance(self) -> float: ...
    @property
    def method(self) -> str: ...
    @property
    def reason(self) -> str: ...
    @property
    def transform(self) -> Tuple[float, float, float]:
        """(tx, ty, theta): b's map frame into a's, metres and degrees: a point p of b (metres, in the
        frame b's origin defines; a bare image's lower-left corner is (0, 0)) lies at
        R(theta) p + (tx, ty) in a's, R(theta) = [[cos, -sin], [sin, cos]]; `fleetmap merge`'s tx_m,
        ty_m, theta_deg. The best candidate even when not merged."""
    @property
    def pixel_transform(self) -> Tuple[float, float, float]:
        """(tx, ty, theta): pixel (u, v) of b (u = column, v = row from the top) lies at
        scale R(theta) (u, v) + (tx, ty) in a's pixel grid, theta in degrees; `fleetmap merge`'s
        tx_px, ty_px, theta_px_deg."""
    @property
    def scale(self) -> float:
        """b's metres per cell / a's."""
    @property
    def covariance(self) -> Optional[npt.NDArray[np.float64]]:
        """3 x 3 covariance of `transform`'s (tx, ty, theta) in metres, metres and radians, from the
        fit of the walls; None without one."""
    @property
    def std(self) -> Optional[Tuple[float, float, float]]:
        """(std_tx_m, std_ty_m, std_theta_deg) of `transform`; None without a covariance."""
    @property
    def uncertain_direction(self) -> Optional[Tuple[float, float, float]]:
        """(std_major_m, std_minor_m, major_direction_deg) where the maps overlap; None without a
        covariance."""
    @property
    def map(self) -> Optional[Map]:
        """The fused map in a's frame and resolution, cut to the known cells and half a metre around
        them (what `fleetmap merge a b --out merged.yaml` writes); None when not merged."""

class PlanResult:
    planner: str
    length_m: float
    detail: str
    @property
    def success(self) -> bool: ...
    @property
    def status(self) -> str: ...
    @property
    def path(self) -> npt.NDArray[np.float64]:
        """(N, 2) waypoints in metres, from the start to the goal; empty unless success."""

class ExplorationResult:
    metrics: dict
    coverage: npt.NDArray[np.float64]
    trajectories: list[npt.NDArray[np.float64]]
    estimates: list[npt.NDArray[np.float64]]
    steps: int
    finished: bool
    @property
    def merged_map(self) -> Map: ...
    @property
    def robot_maps(self) -> list[Map]: ...
    def save(self, folder: PathLike) -> list[str]: ...

class AssignmentContext:
    """A strategy's optional fifth assign argument; valid only while assign runs."""
    @property
    def team_indices(self) -> npt.NDArray[np.int32]:
        """(R,) each robot's place in the team, 0..team_size-1 (the rows of poses and costs)."""
    @property
    def team_size(self) -> int: ...
    @property
    def sensor_range(self) -> float:
        """The range sensor's reach, metres."""
    @property
    def params(self) -> dict[str, float | bool | str]:
        """The strategy's declared parameters with this run's values."""
    def target_costs(self) -> npt.NDArray[np.float64]:
        """(T, T) wave costs between the targets' goals, metres (inf: not connected)."""
    def target_gains(self) -> npt.NDArray[np.float64]:
        """(T,) never-observed area each target would reveal, square metres."""

class Strategy(Protocol):
    """What register_strategy expects of the objects its class makes. `poses` (R, 3): x, y in
    metres and heading in radians, (-pi, pi]; `targets` (T, 4): goal x, goal y, frontier cells,
    region; `costs` (R, T) wave metres, inf when unreachable; `claimed` (K, 2) goals teammates drive
    to. Returns a target index or -1 per robot. An assign that takes a fifth parameter also gets
    an AssignmentContext."""
    def assign(self, poses: npt.NDArray[np.float64], targets: npt.NDArray[np.float64],
               costs: npt.NDArray[np.float64], claimed: npt.NDArray[np.float64]) -> Sequence[int]: ...

class StrategyWithContext(Protocol):
    """A Strategy whose assign takes the AssignmentContext too."""
    def assign(self, poses: npt.NDArray[np.float64], targets: npt.NDArray[np.float64],
               costs: npt.NDArray[np.float64], claimed: npt.NDArray[np.float64],
               context: AssignmentContext) -> Sequence[int]: ...

class Planner(Protocol):
    """What register_planner expects of the objects its class makes (cls()): `free` (height, width)
    bool, top row first, True where the robot's centre may be; `origin` the lower-left corner
    (x, y, theta); start and goal (x, y) in metres. Returns the waypoints from start to goal, or
    None for no path."""
    def search(self, free: npt.NDArray[np.bool_], resolution: float, origin: Tuple[float, float, float],
               start: Tuple[float, float], goal: Tuple[float, float],
               params: dict[str, Any]) -> Optional[Sequence[Tuple[float, float]]]: ...

class MapAligner(Protocol):
    """What register_map_aligner expects of the objects its class makes (cls()): the two robots' maps
    and estimated poses, each in its own frame. Returns None (not merged) or the sender's frame into
    the receiver's (tx, ty, theta, confidence), metres and radians, confidence in [0, 1]."""
    def align(self, receiver_map: Map, sender_map: Map, receiver_pose: Tuple[float, float, float],
              sender_pose: Tuple[float, float, float],
              params: dict[str, Any]) -> Optional[Tuple[float, float, float, float]]: ...

class Localizer(Protocol):
    """What register_localizer expects of the objects its class makes (cls(initial_pose, params,
    seed)); update_scan, covariance and change_frame are optional."""
    def predict(self, dx: float, dy: float, dtheta: float) -> None: ...
    def update_scan(self, ranges: npt.NDArray[np.float64], angles: npt.NDArray[np.float64],
                    max_range: float) -> None: ...
    def pose(self) -> Tuple[float, float, float]: ...
    def covariance(self) -> npt.ArrayLike: ...
    def change_frame(self, tx: float, ty: float, theta: float) -> None: ...

class MergeMethod(Protocol):
    """What register_merge_method expects of the objects its class makes (cls(params)): the two maps
    as the merge sees them (perhaps cut to their known cells; their origins say where). Returns
    candidates (tx, ty, theta[, score]) taking b's frame into a's, metres and radians, which the
    common pipeline refines and decides on."""
    def propose(self, a: Map, b: Map) -> Sequence[Tuple[float, ...]]: ...

def explore(scenario: Union[None, Mapping[str, Any], PathLike] = None, **keys: Any) -> ExplorationResult: ...
def sweep(spec: Union[None, Mapping[str, Any], PathLike] = None, jobs: int = 1, out: Optional[PathLike] = None,
          **keys: Any) -> list[dict[str, Any]]:
    """The rows of results.csv, one dict per run; with `out`, also the folder `fleetmap bench --out` writes."""
def save_results(rows: Iterable[Mapping[str, Any]], path: PathLike) -> None:
    """Writes sweep rows as `fleetmap bench` writes results.csv (the columns and formats every bench verb reads)."""
def load_map(source: str, resolution: float = 0.05) -> Map:
    """A built-in map by name (map_names()) or a PNG/PGM/map_server YAML file."""
def save_map(map: Map, path: PathLike) -> None: ...
def merge_maps(a: Map, b: Map, method: str = "auto", min_confidence: float = 0.5, seed: int = 1,
               params: Mapping[str, Mapping[str, Any]] | None = None) -> MergeResult:
    """Aligns b to a as `fleetmap merge a b` does: `transform` in metres and degrees, `map` the fused map."""
def plan_path(map: Map, start: Sequence[float], goal: Sequence[float], planner: str = "astar",
              robot_radius: float = 0.2, time_budget: float = 1.0, seed: int = 1,
              params: Mapping[str, Any] | None = None) -> PlanResult: ...
def register_strategy(name: str, cls: Any, help: str = "", joint: bool = True,
                      params: Mapping[str, Any] | None = None) -> None: ...
def register_planner(name: str, cls: Any, help: str = "", params: Mapping[str, Any] | None = None,
                     complete: bool = False) -> None: ...
def register_map_aligner(name: str, cls: Any, help: str = "", params: Mapping[str, Any] | None = None) -> None: ...
def register_localizer(name: str, cls: Any, help: str = "", params: Mapping[str, Any] | None = None) -> None: ...
def register_merge_method(name: str, cls: Any, help: str = "", params: Mapping[str, Any] | None = None) -> None: ...
def strategies() -> list[dict[str, Any]]: ...
def localizers() -> list[dict[str, Any]]: ...
def map_aligners() -> list[dict[str, Any]]: ...
def planners() -> list[dict[str, Any]]: ...
def map_names() -> list[str]: ...
def strategy_names() -> list[str]: ...
def keep_freed_memory() -> bool:
    """Asks the C library to keep freed memory for reuse, for the whole process; call it once in a script
    that merges or explores large maps over and over. False where the C library has no such settings."""
    ...
def planner_names() -> list[str]: ...
def merge_method_names() -> list[str]: ...
def merge_methods() -> list[dict[str, Any]]: ...
