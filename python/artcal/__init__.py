"""artcal: plan and run the kinematic calibration of measuring mechanisms with artifacts.

The results are the JSON documents the command line prints with ``--json`` (same library
functions, same numbers), as :class:`Result` dicts with numpy views added as attributes.
Units are those of the files: mm and degrees. Bad input raises :class:`InputError` (a run that
cannot be done: :class:`RunError`) whose message is the command line's ``error:`` line.
See docs/python.md.
"""

from __future__ import annotations

import copy
import functools
import os
import warnings
from typing import Any, Callable, Dict, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _native
from ._native import Error, InputError, RunError

__all__ = [
    "Error", "InputError", "RunError", "Plan", "Result", "Evaluator", "export_urdf",
    "export_xacro", "export_ur", "export_linuxcnc",
    "import_readings", "import_urdf", "load_plan", "optimize", "optimize_sweep", "placement",
    "station",
]

PLAN_FORMAT = "artcal-plan/1"

PathLike = Union[str, "os.PathLike[str]"]


class Result(dict):
    """A command's JSON document (``artcal COMMAND --json``) with numpy views as attributes.

    The dict itself equals the command line's JSON; the attributes are arrays derived from it
    (or, for ``evaluate``, computed beside it), never extra keys.
    """

    def __init__(self, document: Mapping[str, Any], **arrays: Any) -> None:
        super().__init__(document)
        for name, value in arrays.items():
            setattr(self, name, value)


def _labelled_matrix(block: Optional[Mapping[str, Any]]):
    if block is None:
        return [], np.zeros((0, 0))
    return list(block["parameters"]), np.asarray(block["matrix"], dtype=float)


def _plain(value: Any) -> Any:
    """``value`` with numpy arrays and scalars as lists and numbers (the JSON form)."""
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, Mapping):
        return {key: _plain(item) for key, item in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(item) for item in value]
    return value


def _real_array(value: Any, what: str) -> np.ndarray:
    """``value`` as a float array; InputError (naming ``what``) for complex, bool, text or object
    entries, which ``np.asarray(..., dtype=float)`` would convert or truncate without a word."""
    array = np.asarray(value)
    if array.dtype.kind not in "iuf":
        raise InputError(f"{what}: expected real numbers (mm, deg), got an array of "
                         f"{array.dtype} ({array.dtype.kind!r} entries)")
    return array.astype(float)


def _feature_index(value: Any, what: str) -> int:
    """A feature index: a whole number (0.5, True, "1" and complex numbers are refused)."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer,
                                                                      np.floating)):
        raise InputError(f"{what}: expected a whole number (a feature index), got {value!r}")
    if not float(value).is_integer():
        raise InputError(f"{what}: expected a whole number (a feature index), got {value!r}")
    return int(value)


def _feature_blocks(joints: Any, features: Any) -> list[tuple[int, np.ndarray]]:
    """(feature, (n, k) readings) blocks from the forms add_placement takes."""
    if features is not None:
        q = _real_array(joints, "joints")
        f = np.asarray(features).reshape(-1)
        if q.ndim != 2 or q.shape[0] != f.shape[0]:
            raise ValueError("joints: expected an (n, joints) array with one feature per row, "
                             f"got {q.shape} readings and {f.shape[0]} features")
        return [(_feature_index(fi.item() if isinstance(fi, np.generic) else fi,
                                f"features/{i}"), q[i:i + 1]) for i, fi in enumerate(f)]
    items = joints.items() if isinstance(joints, Mapping) else enumerate(joints)
    blocks = []
    for feature, readings in items:
        q = _real_array(readings, f"joints of feature {feature}")
        if q.ndim == 1:
            q = q.reshape(1, -1)
        if q.ndim != 2:
            raise ValueError(f"joints of feature {feature}: expected an (n, joints) array, "
                             f"got shape {q.shape}")
        blocks.append((_feature_index(feature, f"feature {feature!r}"), q))
    return blocks


def _numbers(check_finite: bool = False, **numbers: Any) -> None:
    """InputError naming the option, as the command line does, for a number argument that is not
    a number: True is not 1, "5" not 5 (the command line reads decimal numbers only); with
    ``check_finite`` also for NaN and inf (``--cube: inf: expected a finite number``)."""
    for name, value in numbers.items():
        if value is None:
            continue
        option = f"--{name.replace('_', '-')}"
        for x in np.ravel(np.asarray(value, dtype=object)):
            if isinstance(x, (bool, np.bool_)) or not isinstance(x, (int, float, np.integer,
                                                                     np.floating)):
                raise InputError(f"{option}: {x!r}: expected a number, got "
                                 f"{type(x).__name__}")
            if check_finite and not np.isfinite(float(x)):
                raise InputError(f"{option}: {float(x)}: expected a finite number")


def _finite(**numbers: Any) -> None:
    """_numbers, finite."""
    _numbers(True, **numbers)


def _input_errors(function: Callable) -> Callable:
    """``function`` raising InputError with one short line where the C++ core refuses an
    argument's type (pybind11's TypeError prints every overload's signature)."""
    @functools.wraps(function)
    def call(*args: Any, **kwargs: Any) -> Any:
        try:
            return function(*args, **kwargs)
        except TypeError as error:
            if "incompatible function arguments" not in str(error) and \
                    "incompatible constructor arguments" not in str(error):
                raise
            raise InputError(f"{function.__qualname__}: an argument is not of its type "
                             f"(help(artcal.{function.__qualname__}) lists them)") from None
    return call


def placement(artifact: str, joints: Any, features: Any = None, *,
              pose: Optional[Mapping[str, Any]] = None,
              name: Optional[str] = None) -> dict[str, Any]:
    """One placement in the plan's JSON form (docs/plan-format.md, ``placements``).

    ``joints``: the readings in file units (mm, deg), either per feature -- a list whose k-th
    item is feature k's (n, joints) array, or a dict {feature: (n, joints) array} -- or one
    (n, joints) array with ``features`` (n,) naming each row's feature (what
    :meth:`Plan.readings` returns). Each row is one measurement, in the order given.
    """
    entry: dict[str, Any] = {"artifact": artifact}
    if name is not None:
        entry["name"] = name
    if pose is not None:
        entry["pose"] = _plain(pose)
    entry["measurements"] = [{"feature": feature, "joints": row.tolist()}
                             for feature, rows in _feature_blocks(joints, features)
                             for row in rows]
    return entry


def station(artifact: str, joints: Any, points: Any, *, stationing: Any = None,
            name: Optional[str] = None) -> dict[str, Any]:
    """One station of an instrument (a laser tracker, a total station; docs/instruments.md) in
    the plan's JSON form: ``joints`` an (n, joints) array of readings (deg, mm), ``points`` the
    (n, 3) points the instrument measured (mm, its own frame), or (n, 6) for a pose instrument
    (x, y, z, then the orientation as a rotation vector, deg); ``stationing`` an optional (n,)
    boolean mask of the readings ``verify`` fits the station on (the others are held out)."""
    q = _real_array(joints, "joints")
    x = _real_array(points, "points")
    if q.ndim == 1:
        q = q.reshape(1, -1)
    if x.ndim == 1:
        x = x.reshape(1, -1)
    if q.ndim != 2 or x.ndim != 2 or q.shape[0] != x.shape[0] or x.shape[1] not in (2, 3, 6):
        raise ValueError("station: expected (n, joints) readings and (n, 3) points (n, 6 for a "
                         f"pose instrument), got {q.shape} and {x.shape}")
    marks = None
    if stationing is not None:
        marks = np.asarray(stationing).reshape(-1)
        if marks.dtype.kind != "b" or marks.shape[0] != q.shape[0]:
            raise ValueError(f"stationing: expected {q.shape[0]} booleans, one per reading")
    entry: dict[str, Any] = {"artifact": artifact}
    if name is not None:
        entry["name"] = name
    entry["measurements"] = []
    for i in range(q.shape[0]):
        reading: dict[str, Any] = {"joints": q[i].tolist(), "point": x[i].tolist()}
        if marks is not None and bool(marks[i]):
            reading["stationing"] = True
        entry["measurements"].append(reading)
    return entry


class Plan:
    """An artcal plan (artcal-plan/1): read from a file, from a dict of the same form, or built
    in code from its parts (the same JSON form, parsed by the library's plan reader)."""

    def __init__(self, path: Optional[PathLike] = None, *, machine: Optional[Mapping] = None,
                 noise: Optional[Mapping] = None, artifacts: Optional[Mapping] = None,
                 placements: Optional[list] = None, workspace: Optional[Mapping] = None,
                 name: Optional[str] = None, source: str = "<plan>",
                 require_placements: bool = True, **other: Any) -> None:
        """``Plan(path)`` reads the plan file (as ``artcal check PLAN`` does).

        ``Plan(machine=..., noise=..., artifacts=..., placements=..., workspace=..., name=...)``
        builds one in code: each part is the plan file's block (dicts, numpy arrays accepted),
        ``placements`` a list of :func:`placement` entries; further top-level blocks
        (``description``, ``acceptance``, ``design``) as keywords. :meth:`add_artifact` and
        :meth:`add_placement` add to it. The plan is read (and checked) when first used; errors
        name ``source`` as the file.
        """
        self._require_placements = require_placements
        if path is not None:
            if any(v is not None for v in (machine, noise, artifacts, placements, workspace,
                                           name)) or other:
                raise TypeError("Plan(path) reads a file: give either a path or the parts")
            self._set_native(_native.load_plan(os.fspath(path), require_placements))
            return
        document: dict[str, Any] = {"format": PLAN_FORMAT}
        if name is not None:
            document["name"] = name
        parts = {"machine": machine, "noise": noise, "artifacts": artifacts,
                 "placements": placements, "workspace": workspace, **other}
        document.update({key: _plain(value) for key, value in parts.items()
                         if value is not None})
        document.setdefault("artifacts", {})
        document.setdefault("placements", [])
        self._document = document
        self._source = source
        self._native_plan = None

    def _set_native(self, native: Any) -> None:
        self._native_plan = native
        self._document = None
        self._source = native.source

    @property
    def _plan(self) -> Any:
        """The library's plan, read from the document when first needed."""
        if self._native_plan is None:
            self._native_plan = _native.plan_from_dict(self._document, self._source,
                                                       self._require_placements)
        return self._native_plan

    @classmethod
    def from_dict(cls, document: Mapping[str, Any], *, source: str = "<dict>",
                  require_placements: bool = True) -> "Plan":
        """A plan from its JSON form as a dict; errors name ``source`` as the file."""
        plan = cls.__new__(cls)
        plan._require_placements = require_placements
        plan._set_native(_native.plan_from_dict(_plain(document), source, require_placements))
        return plan

    def _editable(self) -> dict[str, Any]:
        if self._document is None:
            self._document = self._native_plan.document()
        self._native_plan = None  # read again, with the addition, when next used
        return self._document

    def add_artifact(self, artifact_id: str, type: str, **fields: Any) -> "Plan":
        """Adds an artifact (the ``artifacts`` block's entry, e.g. ``add_artifact("bar80",
        "ball_bar", length=80.0, u_length=0.0)``); returns the plan."""
        self._editable().setdefault("artifacts", {})[artifact_id] = {"type": type,
                                                                   **_plain(fields)}
        return self

    def add_placement(self, artifact: str, joints: Any, features: Any = None, *,
                      pose: Optional[Mapping[str, Any]] = None,
                      name: Optional[str] = None) -> "Plan":
        """Adds a placement of ``artifact`` with its readings (see :func:`placement`: per
        feature (n, joints) arrays, or one (n, joints) array and ``features``; mm, deg);
        returns the plan."""
        document = self._editable()
        kind = document.get("artifacts", {}).get(artifact, {})
        if isinstance(kind, Mapping) and kind.get("type") == "instrument":
            raise InputError(f"{self._source}: /artifacts/{artifact}: an instrument: its readings "
                             "are joints and the measured points, without features: use "
                             "add_station(artifact, joints, points)")
        entry = placement(artifact, joints, features, pose=pose, name=name)
        document.setdefault("placements", []).append(entry)
        return self

    def add_station(self, artifact: str, joints: Any, points: Any, *, stationing: Any = None,
                    name: Optional[str] = None) -> "Plan":
        """Adds a station of the instrument ``artifact`` with its readings and measured points
        (see :func:`station`: (n, joints) readings, (n, 3) points, mm, deg); returns the plan."""
        entry = station(artifact, joints, points, stationing=stationing, name=name)
        self._editable().setdefault("placements", []).append(entry)
        return self

    @property
    def name(self) -> str:
        """The plan's name."""
        return self._plan.name

    @property
    def source(self) -> str:
        """The file (or the source name) the plan was read from."""
        return self._source

    @property
    def warnings(self) -> list[str]:
        """The warnings of reading it (unknown fields), as the command line prints them."""
        return list(self._plan.warnings)

    def to_dict(self) -> dict[str, Any]:
        """The plan document as read (or as built)."""
        if self._document is not None:
            return copy.deepcopy(self._document)
        return self._plan.document()

    @property
    def placement_count(self) -> int:
        """How many placements the plan has."""
        return self._plan.placement_count()

    def readings(self, placement: int) -> tuple[np.ndarray, np.ndarray]:
        """One placement's joint readings as an (n, joints) array in file units (mm, deg), inline
        or from its CSV files, and each reading's feature index (n,)."""
        joints, features, _, _ = self._plan.readings(placement)
        n_joints = len(joints[0]) if joints else 0
        return (np.asarray(joints, dtype=float).reshape(len(joints), n_joints),
                np.asarray(features, dtype=int))

    def check(self, *, rank_tol: float = 1e-10) -> Result:
        """``artcal check --json``: counting condition and rank."""
        _finite(rank_tol=rank_tol)
        return Result(self._plan.check(rank_tol))

    def evaluate(self, *, rank_tol: float = 1e-10, profile_steps: int = 21,
                 per_configuration: bool = True) -> Result:
        """``artcal evaluate --json``: parameter uncertainties and the tip uncertainty.

        Attributes: ``parameter_names`` (list), ``u`` (ndarray, file units), ``covariance``
        (ndarray, file units, rows/columns in ``parameter_names`` order), and with
        ``per_configuration`` the tip uncertainty at each workspace configuration:
        ``tip_total``, ``tip_kinematic``, ``tip_encoder`` (mm) and ``tip_joints`` (n, joints).
        """
        _finite(rank_tol=rank_tol)
        document, covariance, tip = self._plan.evaluate(rank_tol, profile_steps,
                                                        per_configuration)
        names, matrix = _labelled_matrix(covariance)
        arrays = {
            "parameter_names": [p["name"] for p in document.get("parameters", [])],
            "u": np.asarray([np.nan if p["u"] is None else p["u"]
                             for p in document.get("parameters", [])], dtype=float),
            "covariance": matrix,
        }
        if tip:
            arrays["tip_total"] = tip["total"]
            arrays["tip_kinematic"] = tip["kinematic"]
            arrays["tip_encoder"] = tip["encoder"]
            arrays["tip_joints"] = tip["joints"]
        return Result(document, **arrays)

    def calibrate(self, *, max_iterations: int = 200, step_tol: float = 1e-3,
                  flag_threshold: float = 3.0, gross_threshold: float = 5.0) -> Result:
        """``artcal calibrate --json`` on the plan's readings (GIL released).

        Attributes: ``parameter_names``, ``estimates`` (ndarray, file units), ``covariance``
        (ndarray, file units, None when not computed), ``residuals`` (the JSON rows, each with
        the CSV row it came from when the readings were imported), ``converged`` and ``machine``
        (the machine block ``--write-machine`` writes, None when not converged).
        """
        _finite(step_tol=step_tol, flag_threshold=flag_threshold, gross_threshold=gross_threshold)
        document, machine = self._plan.calibrate(max_iterations, step_tol, flag_threshold,
                                                 gross_threshold)
        parameters = document.get("parameters", [])
        covariance = None
        if machine is not None and "covariance" in machine:
            covariance = _labelled_matrix(machine["covariance"])[1]
        return Result(document,
                      parameter_names=[p["name"] for p in parameters],
                      estimates=np.asarray([p.get("estimate", np.nan) for p in parameters],
                                           dtype=float),
                      covariance=covariance,
                      residuals=document.get("residuals", []),
                      converged=bool(document.get("converged", False)),
                      machine=machine)

    def verify(self, machine: Union[PathLike, Mapping[str, Any], None] = None) -> Result:
        """``artcal verify --json [--machine FILE]``: a (calibrated) machine on these readings;
        ``machine`` is a machine file's path or the dict ``calibrate().machine``."""
        return Result(self._plan.verify(_machine_arg(machine)))

    def simulate(self, truth: Union[PathLike, Mapping[str, Any]], *, seed: int = 1,
                 noise_scale: float = 1.0, artifact_errors: bool = True) -> "Plan":
        """``artcal simulate --truth TRUTH -o -``: the plan with simulated readings."""
        if isinstance(truth, os.PathLike):
            truth = os.fspath(truth)
        _finite(noise_scale=noise_scale)
        document = self._plan.simulate(truth, seed, noise_scale, artifact_errors)
        return Plan.from_dict(document, source=self.source)

    def confirm(self, *, trials: int = 200, seed: int = 1, threads: int = 0,
                noise_scale: float = 1.0, perturbation: float = 3.0, level: float = 0.01,
                allowance: float = 0.05,
                progress: Optional[Callable[[int, int], None]] = None) -> Result:
        """``artcal confirm --json``: Monte-Carlo confirmation (GIL released);
        ``progress(done, total)`` is called as trials finish."""
        _finite(noise_scale=noise_scale, perturbation=perturbation, level=level,
                allowance=allowance)
        return Result(self._plan.confirm(trials, seed, threads, noise_scale, perturbation, level,
                                         allowance, progress))

    def acceptance_length(self, mpe: str, *, machine: Union[PathLike, Mapping[str, Any],
                                                           None] = None,
                          posterior: bool = False, trials: int = 0, seed: int = 20261201,
                          threads: int = 0, stylus_offset: float = 0.0) -> Result:
        """``artcal acceptance PLAN --test iso10360-2 --mpe MPE --json`` (ISO 10360-2) from the
        plan's predicted V_p; with ``machine`` (a machine file's path or the dict
        ``calibrate().machine``) ``artcal acceptance MACHINE --plan PLAN [--posterior]``: the
        calibrated machine's covariance on this plan's noise and workspace. ``stylus_offset``
        (mm, e.g. 150): ``--stylus-offset``, the E150 test."""
        _numbers(stylus_offset=stylus_offset)  # its range: the prediction's own check
        return Result(self._plan.acceptance_length(mpe, trials, seed, threads,
                                                   _machine_arg(machine), posterior,
                                                   stylus_offset))

    def acceptance_pose(self, cube: float, center: tuple[float, float, float], *,
                        mpe: Optional[float] = None,
                        machine: Union[PathLike, Mapping[str, Any], None] = None,
                        posterior: bool = False, trials: int = 0, seed: int = 20261201,
                        threads: int = 0) -> Result:
        """``artcal acceptance PLAN --test iso9283 --cube E --center X,Y,Z --json`` (ISO 9283);
        ``machine`` and ``posterior`` as in :meth:`acceptance_length`."""
        _finite(cube=cube, center=center, mpe=mpe)
        return Result(self._plan.acceptance_pose(cube, tuple(center), mpe, trials, seed,
                                                 threads, _machine_arg(machine), posterior))

    def __repr__(self) -> str:
        return f"artcal.Plan({self.source!r})"


for _method in ("__init__", "add_artifact", "add_placement", "add_station", "readings", "check",
                "evaluate", "calibrate", "verify", "simulate", "confirm", "acceptance_length",
                "acceptance_pose"):
    setattr(Plan, _method, _input_errors(getattr(Plan, _method)))
Plan.from_dict = classmethod(_input_errors(Plan.from_dict.__func__))


class Evaluator:
    """The prepared evaluation of a plan's placements (the optimizer's inner loop):
    ``tip()`` returns (worst, mean, rms) of the tip uncertainty, mm, or None."""

    def __init__(self, plan: Plan) -> None:
        """Prepares the plan's workspace (its Jacobians, once)."""
        self._evaluator = _native._Evaluator(plan._plan)

    def tip(self) -> Optional[tuple[float, float, float]]:
        """(worst, mean, rms) of the tip uncertainty over the plan's workspace, mm; None when the
        placements do not identify the calibrated parameters."""
        return self._evaluator.tip()


@_input_errors
def load_plan(path: PathLike, *, require_placements: bool = True) -> Plan:
    """Reads a plan file (same as ``Plan(path)``)."""
    return Plan(path, require_placements=require_placements)


@_input_errors
def import_urdf(path: PathLike, base: str, tip: Union[str, Sequence[str]]) -> dict[str, Any]:
    """``artcal import-urdf URDF --base BASE --tip TIP [--tip TIP2 ...]``: the machine block
    (mm, deg); several tips give one machine whose shared joints appear once (docs/urdf.md)."""
    tips = [tip] if isinstance(tip, str) else list(tip)
    return _native.import_urdf(os.fspath(path), base, tips)


def _machine_arg(machine: Any) -> Any:
    """A machine file's path as str, a dict in its JSON form, None as None."""
    if isinstance(machine, os.PathLike):
        return os.fspath(machine)
    if isinstance(machine, Mapping):
        return _plain(machine)
    return machine


def _spec_plan(spec: Union[PathLike, Mapping[str, Any], Plan]) -> Any:
    if isinstance(spec, Plan):
        return spec._plan
    if isinstance(spec, Mapping):
        return _native.plan_from_dict(_plain(spec), "<dict>", False)
    return _native.load_plan(os.fspath(spec), False)


def _optimize_knobs(starts, seed, time_limit, threads, pool, evaluations, polish, kicks,
                    algorithm) -> Any:
    knobs = _native._OptimizeKnobs()
    knobs.starts, knobs.seed, knobs.time_limit, knobs.threads = starts, seed, time_limit, threads
    knobs.pool, knobs.evaluations, knobs.polish, knobs.kicks = pool, evaluations, polish, kicks
    knobs.algorithm = algorithm
    return knobs


@_input_errors
def optimize(spec: Union[PathLike, Mapping[str, Any], Plan], *, starts: Optional[int] = None,
             seed: Optional[int] = None, time_limit: Optional[float] = None, threads: int = 0,
             pool: Optional[int] = None, evaluations: Optional[int] = None,
             polish: Optional[int] = None, kicks: Optional[int] = None,
             algorithm: str = "sbplx",
             progress: Optional[Callable[[int, int, float, float], None]] = None) -> Plan:
    """``artcal optimize SPEC -o PLAN``: the optimized plan, equal to the file the command
    writes (its ``predicted`` block with the search's ``optimization`` record; GIL released).
    The keywords are the command's options (None: the spec's design block);
    ``progress(starts_done, starts, best, seconds)`` after each start."""
    native = _spec_plan(spec)
    knobs = _optimize_knobs(starts, seed, time_limit, threads, pool, evaluations, polish, kicks,
                            algorithm)
    document = native.optimize(knobs, progress)
    return Plan.from_dict(document, source=native.source)


@_input_errors
def optimize_sweep(spec: Union[PathLike, Mapping[str, Any], Plan], placements: str,
                   directory: PathLike, *, target_tip: Optional[float] = None,
                   starts: Optional[int] = None, seed: Optional[int] = None,
                   time_limit: Optional[float] = None, threads: int = 0,
                   pool: Optional[int] = None, evaluations: Optional[int] = None,
                   polish: Optional[int] = None, kicks: Optional[int] = None,
                   algorithm: str = "sbplx",
                   progress: Optional[Callable[[int, float], None]] = None) -> Result:
    """``artcal optimize SPEC --placements A..B -o DIR --json``: every count from A to B
    optimized, the plans and summary.json/.txt/.svg written into ``directory`` (GIL released).
    Returns the summary document (what ``--json`` prints) with ``plans``: {count: Plan} of the
    plans written. ``progress(count, criterion_mm)`` after each count."""
    native = _spec_plan(spec)
    knobs = _optimize_knobs(starts, seed, time_limit, threads, pool, evaluations, polish, kicks,
                            algorithm)
    summary, files = native.optimize_sweep(knobs, placements, target_tip, os.fspath(directory),
                                           progress)
    plans = {}
    for path in files:
        plan = Plan(path)
        plans[plan.to_dict()["design"]["placements"]] = plan
    return Result(summary, plans=plans)


def _prior_tolerances(prior: Any) -> None:
    """``prior`` as the command line's --prior LENGTH,ANGLE: two numbers, each > 0 ((0, 0) is no
    prior the command line would take, True no 1)."""
    numbers = list(prior) if isinstance(prior, (tuple, list)) else [prior]
    _finite(prior=numbers)
    if len(numbers) != 2 or not all(float(x) > 0.0 for x in numbers):
        raise InputError(f"--prior: {tuple(numbers)!r}: expected (LENGTH, ANGLE), numbers > 0 "
                         "(mm, deg), e.g. (5, 0.5)")


@_input_errors
def import_readings(folder: Union[PathLike, Sequence[PathLike]], *,
                    urdf: Optional[PathLike] = None, base: Optional[str] = None,
                    tip: Union[str, Sequence[str], None] = None,
                    machine: Optional[PathLike] = None, ball_bar: Optional[float] = None,
                    u_length: float = 0.0, artifact: Optional[PathLike] = None,
                    probe: Union[float, str, None] = None, encoder: float = 0.0,
                    unit: Optional[str] = None, keep_calibrate: bool = False,
                    keep_limits: bool = False, output: Optional[PathLike] = None,
                    instrument: Optional[float] = None,
                    point_unit: Optional[str] = None,
                    instrument_angle: Optional[float] = None,
                    orientation_unit: Optional[str] = None,
                    marker: Union[str, Sequence[str], None] = None,
                    orientation: Optional[str] = None,
                    hold: Optional[Mapping[str, float]] = None,
                    tip_of: Optional[Mapping[str, str]] = None,
                    prior: Optional[Tuple[float, float]] = None) -> Plan:
    """``artcal import-readings FOLDER (--urdf U --base B --tip T | --machine M) (--ball-bar L |
    --artifact A | --instrument NOISE) [-o OUTPUT]``: the plan of a folder of CSV readings (one
    sub-folder per placement, one file per feature; with ``instrument``, one CSV file per
    station: joints then x, y, z; with ``instrument_angle`` too, a pose instrument of this
    orientation noise in deg, each row the joints then x, y, z, rx, ry, rz; docs/instruments.md).
    ``probe`` in mm (or "estimate"; default 0.1, "estimate" beside an instrument), ``encoder`` in
    deg, ``point_unit`` "mm" or "m", ``orientation_unit`` "deg" or "rad". Files whose header
    names the columns (docs/plan-format.md): ``marker`` the marker whose <marker>_x, _y, _z are
    the tip's point (a list of several: one reading of each per row, each marker a tip whose
    offset is calibrated), ``orientation`` "rotation_vector", "rpy" (fixed-axis x-y-z) or "quaternion"
    (w first), ``hold`` {joint: value} for joints no file reads (deg, or mm). ``folder`` may be a
    list of CSV files, one placement each (a plane's touches, docs/planes.md); ``tip`` a list of
    tips (one machine, several tips) with ``tip_of`` {placement: tip}; ``prior`` (mm, deg) the
    machine's tolerances as built. With ``output`` the plan is also written there (CSV paths relative to
    its folder; without it, to the current folder). The import's warnings (joint limits widened
    to the readings) are in ``plan.warnings``."""
    def text(value: Any) -> str:
        return "" if value is None else os.fspath(value)

    if probe is None:
        probe = "estimate" if instrument is not None else 0.1
    _finite(ball_bar=ball_bar, u_length=u_length, encoder=encoder, instrument=instrument,
            instrument_angle=instrument_angle, probe=None if isinstance(probe, str) else probe)
    _finite(**{f"hold {joint}": value for joint, value in (hold or {}).items()})
    if prior is not None:
        _prior_tolerances(prior)
    files = [] if isinstance(folder, (str, os.PathLike)) else [text(f) for f in folder]
    # An entry given twice counts once (options given twice, docs/hardening.md).
    tips = [] if tip is None or isinstance(tip, str) else list(dict.fromkeys(tip))
    single_tip = tip if isinstance(tip, str) else (tips[0] if len(tips) == 1 else "")
    native = _native.import_readings("" if files else text(folder), text(machine), text(urdf),
                                     base or "", single_tip, ball_bar, u_length, text(artifact),
                                     probe,
                                     encoder, unit or "", keep_calibrate, keep_limits,
                                     text(output), instrument, point_unit or "",
                                     instrument_angle, orientation_unit or "",
                                     [marker] if isinstance(marker, str)
                                     else list(dict.fromkeys(marker or [])),
                                     orientation or "", dict(hold or {}), files, tips,
                                     dict(tip_of or {}), prior)
    plan = Plan.__new__(Plan)
    plan._require_placements = True
    plan._set_native(native)
    return plan


def _export(format_: str, machine: Union[PathLike, Mapping[str, Any]], urdf: str,
            pivot: Sequence[float], output: Optional[PathLike]) -> Tuple[str, Dict[str, Any]]:
    text, summary, warnings_ = _native.export_machine(
        format_, _machine_arg(machine), urdf, [float(v) for v in pivot],
        "" if output is None else os.fspath(output))
    for line in warnings_:
        warnings.warn(line, UserWarning, stacklevel=3)
    return text, summary


@_input_errors
def export_xacro(machine: Union[PathLike, Mapping[str, Any]], urdf: PathLike,
                 output: Optional[PathLike] = None) -> Tuple[str, Dict[str, Any]]:
    """``artcal export-xacro --machine MACHINE --urdf URDF -o OUTPUT`` (docs/exports.md): the
    xacro properties of the calibrated origins and the summary (``--json``'s document)."""
    return _export("xacro", machine, os.fspath(urdf), [], output)


@_input_errors
def export_ur(machine: Union[PathLike, Mapping[str, Any]],
              output: Optional[PathLike] = None) -> Tuple[str, Dict[str, Any]]:
    """``artcal export-ur --machine MACHINE -o OUTPUT`` (docs/exports.md): the Universal Robots
    kinematics_config YAML and the summary (what it cannot carry: the TCP, ...)."""
    return _export("ur", machine, "", [], output)


@_input_errors
def export_linuxcnc(machine: Union[PathLike, Mapping[str, Any]], pivot: Sequence[float],
                    output: Optional[PathLike] = None) -> Tuple[str, Dict[str, Any]]:
    """``artcal export-linuxcnc --machine MACHINE --pivot X Y Z -o OUTPUT`` (docs/exports.md):
    the HAL setp lines of xyzac-trt-kins and the summary (what it cannot carry)."""
    return _export("linuxcnc", machine, "", pivot, output)


@_input_errors
def export_urdf(machine: Union[PathLike, Mapping[str, Any]], urdf: PathLike,
                output: Optional[PathLike] = None) -> str:
    """``artcal export-urdf --machine MACHINE --urdf URDF -o OUTPUT``: the URDF with the chain's
    origins set to the (calibrated) machine's -- a machine file's path or the dict
    ``calibrate().machine`` -- everything else kept. Returns the text, and writes it to
    ``output`` when given (atomically, never over an input). Corrections a metrologist would
    not believe are reported as :class:`UserWarning` (the command's ``warning:`` lines)."""
    text, warnings_ = _native.export_urdf(_machine_arg(machine), os.fspath(urdf),
                                          "" if output is None else os.fspath(output))
    for line in warnings_:
        warnings.warn(line, UserWarning, stacklevel=2)
    return text
