"""Type stubs of sonarbench's C++ core. Units are in the names (_m metres, _rad radians, _s
seconds); poses are T_world_sonar, 4 × 4, the sonar frame at head angle 0 in the world frame."""

import os
from typing import Any, Iterable, Iterator, Optional, Union

import numpy as np
import numpy.typing as npt

_Path = Union[str, os.PathLike[str]]

__version__: str
ECHO_PATHS: tuple[str, ...]
"""The paths a bin's echo energy arrives by, in path_shares' order."""
NO_MESH: int
"""Sweep.mesh's value for a bin no scene mesh answers directly."""

class InputError(ValueError):
    """Bad input: the message names the file, key or argument and what was expected."""

class MachineError(InputError, OSError):
    """The machine refused (a read-only or full disk, no permission)."""

class Sensor:
    """What the mapper knows of the sonar."""
    @property
    def bin_count(self) -> int: ...
    @property
    def bin_size_m(self) -> float: ...
    @property
    def beams_per_sweep(self) -> int: ...
    @property
    def max_range_m(self) -> float: ...

class Sweep:
    """One sweep of beams. Its arrays are read-only views of the sweep (no copies)."""
    def __init__(
        self,
        intensities: npt.ArrayLike,
        head_angles_rad: npt.ArrayLike,
        poses: npt.ArrayLike,
        bin_size_m: float,
        times_s: Optional[npt.ArrayLike] = None,
    ) -> None:
        """A sweep from arrays: intensities (beams × bins, uint8), head angles [rad], poses
        (beams × 4 × 4, T_world_sonar), the bin size [m], times [s] (default 0, 1, 2, ...)."""
    @property
    def index(self) -> int:
        """The sweep's number in its run or log."""
    @property
    def beam_count(self) -> int: ...
    @property
    def bin_size_m(self) -> float:
        """Range of one bin [m]: bin k spans [k, k+1)·bin_size_m."""
    @property
    def intensities(self) -> npt.NDArray[np.uint8]:
        """Echo intensity, beams × bins."""
    @property
    def bin_counts(self) -> npt.NDArray[np.uint32]:
        """Bins each beam has; a shorter beam is padded with zeros in intensities."""
    @property
    def times_s(self) -> npt.NDArray[np.float64]:
        """Time of each ping [s] since the start of the run or log."""
    @property
    def head_angles_rad(self) -> npt.NDArray[np.float64]:
        """Head angle of each beam [rad] about the sonar frame's z axis."""
    @property
    def bin_sizes_m(self) -> npt.NDArray[np.float64]:
        """Range of one bin of each beam [m]."""
    @property
    def poses(self) -> npt.NDArray[np.float64]:
        """T_world_sonar of each beam, beams × 4 × 4 [m], as the mapper is given it."""
    @property
    def labelled(self) -> bool:
        """Whether path_shares, mesh and points_sonar_m are present."""
    @property
    def path_shares(self) -> Optional[npt.NDArray[np.uint8]]:
        """Each path's share of each bin's power in 255ths, beams × bins × 7 (ECHO_PATHS)."""
    @property
    def mesh(self) -> Optional[npt.NDArray[np.uint16]]:
        """The scene mesh with the most direct energy per bin (Scene.mesh_names), or NO_MESH."""
    @property
    def points_sonar_m(self) -> Optional[npt.NDArray[np.float32]]:
        """That mesh's strongest direct return per bin, sonar frame [m], beams × bins × 3."""

class Scene:
    """A scene file loaded with its sensor model."""
    @property
    def name(self) -> str: ...
    @property
    def file(self) -> str: ...
    @property
    def seed(self) -> int: ...
    @property
    def sweeps(self) -> int: ...
    @property
    def beam_count(self) -> int: ...
    @property
    def beams_per_sweep(self) -> int: ...
    @property
    def bin_count(self) -> int: ...
    @property
    def bin_size_m(self) -> float: ...
    @property
    def mesh_names(self) -> list[str]: ...

def load_scene(
    path: _Path, *, max_triangles: float = ..., max_cells: float = ..., max_beams: float = ...
) -> Scene:
    """Loads a scene YAML file and checks its budgets as the command line does."""

class SweepIterator(Iterator[Sweep]):
    def __iter__(self) -> "SweepIterator": ...
    def __next__(self) -> Sweep: ...

class Simulator:
    """A scene's run, simulated sweep by sweep, its world built once."""
    def __init__(self, scene: Scene, *, seed: Optional[int] = None, threads: int = 0) -> None: ...
    @property
    def sweep_count(self) -> int: ...
    @property
    def seed(self) -> int: ...
    def sweep(self, index: int, *, labels: bool = True) -> Sweep:
        """Sweep `index`: the beams `sonarbench simulate` writes for it."""
    def sweeps(self, *, labels: bool = True) -> SweepIterator: ...
    def __len__(self) -> int: ...
    def __getitem__(self, index: int) -> Sweep: ...

class Log:
    """A recorded run read whole."""
    @property
    def source(self) -> str:
        """'dataset', 'mat' or 'mcap'."""
    @property
    def path(self) -> str: ...
    @property
    def sensor(self) -> Sensor: ...
    @property
    def sweeps(self) -> list[Sweep]: ...
    @property
    def beam_count(self) -> int: ...
    @property
    def truncated_beams(self) -> int: ...
    @property
    def manifest(self) -> Optional[dict[str, Any]]: ...
    def __len__(self) -> int: ...

def sensor_model(path: Optional[_Path] = None) -> Sensor: ...
def read_dataset(path: _Path) -> Log: ...
def read_mat(path: _Path, *, sensor_model: Optional[_Path] = None) -> Log: ...
def read_mcap(
    path: _Path, *, sensor_model: Optional[_Path] = None, topic: str = "", static: bool = False
) -> Log: ...

class Mapper:
    """The production mapper."""
    def __init__(
        self,
        *,
        scene: Optional[Scene] = None,
        sensor_model: Optional[_Path] = None,
        sensor: Optional[Sensor] = None,
        threads: int = 0,
        max_cells: float = ...,
        **mapping: Any,
    ) -> None: ...
    def integrate(self, sweep: Sweep) -> dict[str, int]: ...
    def integrate_sweeps(self, sweeps: Iterable[Sweep]) -> dict[str, int]: ...
    def occupied(self) -> npt.NDArray[np.float64]:
        """Centres of the occupied cells, N × 3 [m], world frame, in key order."""
    def free(self) -> npt.NDArray[np.float64]:
        """Centres of the free cells, N × 3 [m], world frame, in key order."""
    def write_bt(self, path: _Path, *, overwrite: bool = False) -> None: ...
    def write_ot(self, path: _Path, *, overwrite: bool = False) -> None: ...
    @property
    def resolution_m(self) -> float: ...
    @property
    def sensor(self) -> Sensor: ...

def score(scene: Scene, map: Union[Mapper, _Path]) -> dict[str, Any]:
    """A map against the scene as `sonarbench score` scores it: 'metrics', 'verdict',
    'criteria' (report.json's) and 'occupied_in_reach'."""
