"""Type stubs of the artcal package (docs/python.md). Units: mm and degrees, as the files."""

import os
from typing import Any, Callable, Dict, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

PathLike = Union[str, os.PathLike[str]]

class Error(ValueError):
    """An artcal error: str(e) is the command line's line without "error: "."""

class InputError(Error):
    """Bad input (the command line's exit status 2): "FILE: POINTER: what to check"."""

class RunError(Error):
    """A valid input that cannot be run as asked (exit status 1)."""

class Result(dict[str, Any]):
    """A command's --json document, numpy views as attributes."""

    parameter_names: list[str]
    u: np.ndarray
    covariance: Optional[np.ndarray]
    tip_total: np.ndarray
    tip_kinematic: np.ndarray
    tip_encoder: np.ndarray
    tip_joints: np.ndarray
    estimates: np.ndarray
    residuals: list[dict[str, Any]]
    converged: bool
    machine: Optional[dict[str, Any]]
    plans: dict[int, Plan]
    def __init__(self, document: Mapping[str, Any], **arrays: Any) -> None: ...

def placement(
    artifact: str,
    joints: Any,
    features: Any = None,
    *,
    pose: Optional[Mapping[str, Any]] = None,
    name: Optional[str] = None,
) -> dict[str, Any]:
    """One placement in the plan's JSON form; joints per feature ((n, joints) arrays, mm/deg) or
    one (n, joints) array with features (n,)."""

def station(
    artifact: str,
    joints: Any,
    points: Any,
    *,
    stationing: Any = None,
    name: Optional[str] = None,
) -> dict[str, Any]:
    """One station of an instrument in the plan's JSON form: (n, joints) readings, (n, 3) or
    (n, 6) measured points (mm, deg), an optional (n,) stationing mask."""

class Plan:
    """An artcal plan (artcal-plan/1): from a file, a dict, or built in code."""

    def __init__(
        self,
        path: Optional[PathLike] = None,
        *,
        machine: Optional[Mapping[str, Any]] = None,
        noise: Optional[Mapping[str, Any]] = None,
        artifacts: Optional[Mapping[str, Any]] = None,
        placements: Optional[list[dict[str, Any]]] = None,
        workspace: Optional[Mapping[str, Any]] = None,
        name: Optional[str] = None,
        source: str = "<plan>",
        require_placements: bool = True,
        **other: Any,
    ) -> None:
        """Plan(path) reads a file; Plan(machine=..., noise=..., ...) builds one in code."""
    def add_artifact(self, artifact_id: str, type: str, **fields: Any) -> Plan:
        """Adds an entry of the artifacts block; returns the plan."""
    def add_placement(
        self,
        artifact: str,
        joints: Any,
        features: Any = None,
        *,
        pose: Optional[Mapping[str, Any]] = None,
        name: Optional[str] = None,
    ) -> Plan:
        """Adds a placement with its readings (see placement()); returns the plan."""
    def add_station(
        self,
        artifact: str,
        joints: Any,
        points: Any,
        *,
        stationing: Any = None,
        name: Optional[str] = None,
    ) -> Plan:
        """Adds a station of an instrument with its readings and measured points (see station())."""
    @classmethod
    def from_dict(
        cls, document: Mapping[str, Any], *, source: str = "<dict>", require_placements: bool = True
    ) -> Plan: ...
    @property
    def name(self) -> str: ...
    @property
    def source(self) -> str: ...
    @property
    def warnings(self) -> list[str]: ...
    def to_dict(self) -> dict[str, Any]: ...
    @property
    def placement_count(self) -> int: ...
    def readings(self, placement: int) -> tuple[np.ndarray, np.ndarray]:
        """Joint readings (n, joints), mm and deg, and each reading's feature (n,)."""
    def check(self, *, rank_tol: float = 1e-10) -> Result:
        """artcal check --json."""
    def evaluate(
        self, *, rank_tol: float = 1e-10, profile_steps: int = 21, per_configuration: bool = True
    ) -> Result:
        """artcal evaluate --json; parameter_names, u, covariance, tip_* arrays."""
    def calibrate(
        self,
        *,
        max_iterations: int = 200,
        step_tol: float = 1e-3,
        flag_threshold: float = 3.0,
        gross_threshold: float = 5.0,
    ) -> Result:
        """artcal calibrate --json; estimates, covariance, residuals, machine."""
    def verify(self, machine: Union[PathLike, Mapping[str, Any], None] = None) -> Result:
        """artcal verify --json [--machine FILE]."""
    def simulate(
        self,
        truth: Union[PathLike, Mapping[str, Any]],
        *,
        seed: int = 1,
        noise_scale: float = 1.0,
        artifact_errors: bool = True,
    ) -> Plan:
        """artcal simulate --truth TRUTH -o -: the plan with simulated readings."""
    def confirm(
        self,
        *,
        trials: int = 200,
        seed: int = 1,
        threads: int = 0,
        noise_scale: float = 1.0,
        perturbation: float = 3.0,
        level: float = 0.01,
        allowance: float = 0.05,
        progress: Optional[Callable[[int, int], None]] = None,
    ) -> Result:
        """artcal confirm --json; progress(done, total)."""
    def acceptance_length(
        self,
        mpe: str,
        *,
        machine: Union[PathLike, Mapping[str, Any], None] = None,
        posterior: bool = False,
        trials: int = 0,
        seed: int = 20261201,
        threads: int = 0,
        stylus_offset: float = 0.0,
    ) -> Result:
        """artcal acceptance PLAN --test iso10360-2 --mpe MPE --json; with machine:
        artcal acceptance MACHINE --plan PLAN [--posterior]; stylus_offset: --stylus-offset
        (E150)."""
    def acceptance_pose(
        self,
        cube: float,
        center: tuple[float, float, float],
        *,
        mpe: Optional[float] = None,
        machine: Union[PathLike, Mapping[str, Any], None] = None,
        posterior: bool = False,
        trials: int = 0,
        seed: int = 20261201,
        threads: int = 0,
    ) -> Result:
        """artcal acceptance PLAN --test iso9283 --cube E --center X,Y,Z --json; with machine:
        artcal acceptance MACHINE --plan PLAN [--posterior]."""

class Evaluator:
    """Prepared evaluation of a plan's placements."""

    def __init__(self, plan: Plan) -> None: ...
    def tip(self) -> Optional[tuple[float, float, float]]:
        """(worst, mean, rms) tip uncertainty, mm; None when not identifiable."""

def load_plan(path: PathLike, *, require_placements: bool = True) -> Plan: ...
def import_urdf(path: PathLike, base: str, tip: str) -> dict[str, Any]:
    """artcal import-urdf URDF --base BASE --tip TIP."""
def import_readings(
    folder: PathLike,
    *,
    urdf: Optional[PathLike] = None,
    base: Optional[str] = None,
    tip: Optional[str] = None,
    machine: Optional[PathLike] = None,
    ball_bar: Optional[float] = None,
    u_length: float = 0.0,
    artifact: Optional[PathLike] = None,
    probe: Union[float, str, None] = None,
    encoder: float = 0.0,
    unit: Optional[str] = None,
    keep_calibrate: bool = False,
    keep_limits: bool = False,
    output: Optional[PathLike] = None,
    instrument: Optional[float] = None,
    point_unit: Optional[str] = None,
    instrument_angle: Optional[float] = None,
    orientation_unit: Optional[str] = None,
    marker: Union[str, Sequence[str], None] = None,
    orientation: Optional[str] = None,
    hold: Optional[Mapping[str, float]] = None,
) -> Plan:
    """artcal import-readings FOLDER (--urdf U --base B --tip T | --machine M) (--ball-bar L |
    --artifact A | --instrument NOISE) [-o OUTPUT]."""
def export_urdf(
    machine: Union[PathLike, Mapping[str, Any]], urdf: PathLike, output: Optional[PathLike] = None
) -> str:
    """artcal export-urdf --machine M --urdf U -o OUTPUT: the URDF text (warnings: UserWarning)."""
def export_xacro(
    machine: Union[PathLike, Mapping[str, Any]], urdf: PathLike, output: Optional[PathLike] = None
) -> Tuple[str, Dict[str, Any]]:
    """artcal export-xacro --machine M --urdf U -o OUTPUT: the properties' text and the summary."""
def export_ur(
    machine: Union[PathLike, Mapping[str, Any]], output: Optional[PathLike] = None
) -> Tuple[str, Dict[str, Any]]:
    """artcal export-ur --machine M -o OUTPUT: the kinematics_config YAML and the summary."""
def export_linuxcnc(
    machine: Union[PathLike, Mapping[str, Any]],
    pivot: Sequence[float],
    output: Optional[PathLike] = None,
) -> Tuple[str, Dict[str, Any]]:
    """artcal export-linuxcnc --machine M --pivot X Y Z -o OUTPUT: the HAL text and the summary."""
def optimize(
    spec: Union[PathLike, Mapping[str, Any], Plan],
    *,
    starts: Optional[int] = None,
    seed: Optional[int] = None,
    time_limit: Optional[float] = None,
    threads: int = 0,
    pool: Optional[int] = None,
    evaluations: Optional[int] = None,
    polish: Optional[int] = None,
    kicks: Optional[int] = None,
    algorithm: str = "sbplx",
    progress: Optional[Callable[[int, int, float, float], None]] = None,
) -> Plan:
    """artcal optimize SPEC -o PLAN (predicted.optimization included);
    progress(starts_done, starts, best_mm, seconds)."""
def optimize_sweep(
    spec: Union[PathLike, Mapping[str, Any], Plan],
    placements: str,
    directory: PathLike,
    *,
    target_tip: Optional[float] = None,
    starts: Optional[int] = None,
    seed: Optional[int] = None,
    time_limit: Optional[float] = None,
    threads: int = 0,
    pool: Optional[int] = None,
    evaluations: Optional[int] = None,
    polish: Optional[int] = None,
    kicks: Optional[int] = None,
    algorithm: str = "sbplx",
    progress: Optional[Callable[[int, float], None]] = None,
) -> Result:
    """artcal optimize SPEC --placements A..B -o DIR --json: the summary; .plans {count: Plan}."""
