"""Type hints of the extension module (the Rust side of the package)."""

from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

class PlumetraceError(Exception):
    """A scenario, campaign or planner error; the message names the file and the key."""

def run(
    scenario: str,
    seed: Optional[int] = None,
    set: Optional[Dict[str, Any]] = None,
    planner: Any = None,
    vehicle: int = 0,
    trajectory: bool = True,
    progress: Optional[Callable[[int], Any]] = None,
    outputs: bool = True,
    **kwargs: Any,
) -> Dict[str, Any]: ...
def run_plume(
    scenario: str,
    out: str,
    seed: Optional[int] = None,
    set: Optional[Dict[str, Any]] = None,
    **kwargs: Any,
) -> str: ...
def scenario_kind(scenario: str) -> str: ...

class RunRecord:
    """A flown mission kept for writing its files."""

    def save(self, out: str) -> List[str]: ...
def presets() -> List[Tuple[str, str]]: ...
def planners() -> List[Tuple[str, str]]: ...
def campaign(
    file: str,
    out: str,
    jobs: Optional[int] = None,
    shard: Union[None, str, Tuple[int, int]] = None,
    seeds: Optional[int] = None,
    progress: Optional[Callable[[int, int], Any]] = None,
) -> Dict[str, Any]: ...
def merge(dirs: Sequence[str], out: str) -> Dict[str, Any]: ...
def benchmark(
    out: str,
    names: Sequence[str] = ...,
    factory: Optional[Callable[[str, int], Any]] = None,
    factory_name: Optional[str] = None,
    tasks: Sequence[str] = ...,
    seeds_per_task: Optional[int] = None,
    jobs: Optional[int] = None,
    progress: Optional[Callable[[str, int, int], Any]] = None,
) -> Dict[str, Any]: ...
def run_columns() -> List[Tuple[str, str, str, str]]: ...

class Plume:
    """The flow and plume of a scenario, stepped on the scenario's `dt_s`."""

    def __init__(
        self,
        scenario: str,
        seed: Optional[int] = None,
        set: Optional[Dict[str, Any]] = None,
        **kwargs: Any,
    ) -> None: ...
    @property
    def name(self) -> str: ...
    @property
    def seed(self) -> int: ...
    @property
    def time_s(self) -> float: ...
    @property
    def dt_s(self) -> float: ...
    @property
    def domain(self) -> Tuple[float, float, float, float]: ...
    @property
    def z_m(self) -> float: ...
    def step(self, n: int = 1) -> None: ...
    def spin_up(self, duration_s: float, dt_s: Optional[float] = None) -> None: ...
    def concentrations(
        self, points: npt.ArrayLike, z: Optional[float] = None
    ) -> Union[float, npt.NDArray[np.float64]]: ...
    def concentration_grid(
        self, x: npt.ArrayLike, y: npt.ArrayLike, z: Optional[float] = None
    ) -> npt.NDArray[np.float64]: ...
    def filaments(self) -> npt.NDArray[np.float64]: ...
    def flow(self, points: npt.ArrayLike) -> npt.NDArray[np.float64]: ...
    def probe_series(
        self,
        duration_s: float,
        every_s: Optional[float] = None,
        points: Optional[npt.ArrayLike] = None,
    ) -> Dict[str, npt.NDArray[np.float64]]: ...
    def mean_maps(
        self,
        x: npt.ArrayLike,
        y: npt.ArrayLike,
        z: float,
        duration_s: float,
        every_s: float,
        threshold: Optional[float] = None,
    ) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
    def stats(self) -> Dict[str, float]: ...

def derive_seed(seed: int, k: int) -> int: ...

class EnvCore:
    def __init__(self, scenario: str, set: Optional[Dict[str, Any]] = None, **kwargs: Any) -> None: ...
    @staticmethod
    def obs_names() -> List[str]: ...
    @staticmethod
    def obs_bounds() -> Tuple[List[float], List[float]]: ...
    @staticmethod
    def info_keys() -> List[str]: ...
    @property
    def decision_period_s(self) -> float: ...
    def reset(self, seed: int) -> Tuple[npt.NDArray[np.float32], Dict[str, Any]]: ...
    def step(
        self, action: npt.NDArray[np.float64]
    ) -> Tuple[npt.NDArray[np.float32], float, bool, bool, Dict[str, Any]]: ...

class ObsCore:
    def __init__(
        self, scenario: str, seed: int, set: Optional[Dict[str, Any]] = None, **kwargs: Any
    ) -> None: ...
    @property
    def decision_period_s(self) -> float: ...
    def observe(self, snapshot: str) -> npt.NDArray[np.float32]: ...
    def command(self, snapshot: str, action: npt.NDArray[np.float64]) -> Dict[str, Any]: ...

class VecEnvCore:
    def __init__(
        self,
        scenario: str,
        n: int,
        same_step: bool = False,
        seeds: Optional[List[int]] = None,
        set: Optional[Dict[str, Any]] = None,
        **kwargs: Any,
    ) -> None: ...
    @property
    def num_envs(self) -> int: ...
    def reset(
        self, seeds: List[int], mask: Optional[List[bool]] = None
    ) -> Tuple[npt.NDArray[np.float32], Dict[str, Any]]: ...
    def step(
        self, actions: npt.NDArray[np.float64]
    ) -> Tuple[
        npt.NDArray[np.float32],
        npt.NDArray[np.float64],
        npt.NDArray[np.bool_],
        npt.NDArray[np.bool_],
        Dict[str, Any],
        Optional[Tuple[npt.NDArray[np.bool_], npt.NDArray[np.float32], Dict[str, Any]]],
    ]: ...
