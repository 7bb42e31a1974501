"""artcal: plan and run the kinematic calibration of measuring mechanisms with artifacts.

The results are the JSON documents the command line prints with ``--json`` (same library
functions, same numbers), as :class:`Result` dicts with numpy views added as attributes.
Units are those of the files: mm and degrees. Bad input raises :class:`InputError` (a run that
cannot be done: :class:`RunError`) whose message is the command line's ``error:`` line.
See docs/python.md.
"""

from __future__ import annotations

import os
from typing import Any, Callable, Mapping, Optional, Union

import numpy as np

from . import _native
from ._native import Error, InputError, RunError

__all__ = [
    "Error", "InputError", "RunError", "Plan", "Result", "Evaluator", "import_urdf",
    "load_plan", "optimize",
]

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


class Plan:
    """An artcal plan (artcal-plan/1), read from a file or from a dict of the same form."""

    def __init__(self, path: PathLike, *, require_placements: bool = True) -> None:
        """Reads the plan file ``path`` (as ``artcal check PLAN`` does)."""
        self._plan = _native.load_plan(os.fspath(path), require_placements)

    @classmethod
    def from_dict(cls, document: Mapping[str, Any], *, source: str = "<dict>",
                  require_placements: bool = True) -> "Plan":
        """A plan from its JSON form as a dict; errors name ``source`` as the file."""
        plan = cls.__new__(cls)
        plan._plan = _native.plan_from_dict(document, source, require_placements)
        return plan

    @property
    def name(self) -> str:
        """The plan's name."""
        return self._plan.name

    @property
    def source(self) -> str:
        """The file (or the source name) the plan was read from."""
        return self._plan.source

    @property
    def warnings(self) -> list[str]:
        """The warnings of reading it (unknown fields), as the command line prints them."""
        return list(self._plan.warnings)

    def to_dict(self) -> dict[str, Any]:
        """The plan document as read."""
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
        return Result(self._plan.check(rank_tol))

    def evaluate(self, *, rank_tol: float = 1e-10, profile_steps: int = 21,
                 per_configuration: bool = True) -> Result:
        """``artcal evaluate --json``: parameter uncertainties and the tip uncertainty.

        Attributes: ``parameter_names`` (list), ``u`` (ndarray, file units), ``covariance``
        (ndarray, file units, rows/columns in ``parameter_names`` order), and with
        ``per_configuration`` the tip uncertainty at each workspace configuration:
        ``tip_total``, ``tip_kinematic``, ``tip_encoder`` (mm) and ``tip_joints`` (n, joints).
        """
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
        if isinstance(machine, os.PathLike):
            machine = os.fspath(machine)
        return Result(self._plan.verify(machine))

    def simulate(self, truth: Union[PathLike, Mapping[str, Any]], *, seed: int = 1,
                 noise_scale: float = 1.0, artifact_errors: bool = True) -> "Plan":
        """``artcal simulate --truth TRUTH -o -``: the plan with simulated readings."""
        if isinstance(truth, os.PathLike):
            truth = os.fspath(truth)
        document = self._plan.simulate(truth, seed, noise_scale, artifact_errors)
        return Plan.from_dict(document, source=self.source)

    def confirm(self, *, trials: int = 200, seed: int = 1, threads: int = 0,
                noise_scale: float = 1.0, perturbation: float = 3.0, level: float = 0.01,
                allowance: float = 0.05,
                progress: Optional[Callable[[int, int], None]] = None) -> Result:
        """``artcal confirm --json``: Monte-Carlo confirmation (GIL released);
        ``progress(done, total)`` is called as trials finish."""
        return Result(self._plan.confirm(trials, seed, threads, noise_scale, perturbation, level,
                                         allowance, progress))

    def acceptance_length(self, mpe: str, *, trials: int = 0, seed: int = 20261201,
                          threads: int = 0) -> Result:
        """``artcal acceptance PLAN --test length --mpe MPE --json`` (ISO 10360-2)."""
        return Result(self._plan.acceptance_length(mpe, trials, seed, threads))

    def acceptance_pose(self, cube: float, center: tuple[float, float, float], *,
                        mpe: Optional[float] = None, trials: int = 0, seed: int = 20261201,
                        threads: int = 0) -> Result:
        """``artcal acceptance PLAN --test pose --cube E --center X,Y,Z --json`` (ISO 9283)."""
        return Result(self._plan.acceptance_pose(cube, tuple(center), mpe, trials, seed,
                                                 threads))

    def __repr__(self) -> str:
        return f"artcal.Plan({self.source!r})"


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


def load_plan(path: PathLike, *, require_placements: bool = True) -> Plan:
    """Reads a plan file (same as ``Plan(path)``)."""
    return Plan(path, require_placements=require_placements)


def import_urdf(path: PathLike, base: str, tip: str) -> dict[str, Any]:
    """``artcal import-urdf URDF --base BASE --tip TIP``: the machine block (mm, deg)."""
    return _native.import_urdf(os.fspath(path), base, tip)


def optimize(spec: Union[PathLike, Mapping[str, Any], Plan], *, starts: Optional[int] = None,
             seed: Optional[int] = None, time_limit: Optional[float] = None, threads: int = 0,
             progress: Optional[Callable[[int, int, float, float], None]] = None) -> Plan:
    """``artcal optimize SPEC -o PLAN``: the optimized plan, its ``predicted`` block included
    (GIL released); ``progress(starts_done, starts, best_mm, seconds)`` after each start."""
    if isinstance(spec, Plan):
        native = spec._plan
    elif isinstance(spec, Mapping):
        native = _native.plan_from_dict(spec, "<dict>", False)
    else:
        native = _native.load_plan(os.fspath(spec), False)
    document = native.optimize(starts, seed, time_limit, threads, progress)
    return Plan.from_dict(document, source=native.source)
