"""sonarbench from Python: simulate a mechanical scanning sonar, map with the production mapper,
score against the scene's truth; NumPy arrays in and out (docs/python.md)."""

from ._core import (
    ECHO_PATHS,
    NO_MESH,
    InputError,
    Log,
    MachineError,
    Mapper,
    Scene,
    Sensor,
    Simulator,
    Sweep,
    SweepIterator,
    __version__,
    load_scene,
    read_dataset,
    read_mat,
    read_mcap,
    score,
    sensor_model,
)

__all__ = [
    "ECHO_PATHS", "NO_MESH", "InputError", "Log", "MachineError", "Mapper", "Scene", "Sensor",
    "Simulator", "Sweep", "SweepIterator", "__version__", "load_scene", "read_dataset",
    "read_mat", "read_mcap", "score", "sensor_model",
]
