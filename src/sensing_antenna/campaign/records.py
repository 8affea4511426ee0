"""Results of one campaign run: what each method estimated from one simulated recording.

A :class:`RunResult` is plain data (JSON round-trip with :meth:`RunResult.to_dict` and
:meth:`RunResult.from_dict`) so it can be stored one file per run and rebuilt into the columnar
table of every run x method (:func:`result_rows`). All values are SI: m, s, rad/s.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from sensing_antenna.campaign.runs import RunSpec

__all__ = [
    "CSV_COLUMNS",
    "METHOD_ERROR",
    "RUN_FAILED",
    "RUN_OK",
    "MethodOutcome",
    "RunResult",
    "float_or_nan",
    "result_rows",
]

#: Run status: the run function returned.
RUN_OK = "ok"
#: Run status: the run function raised; ``error`` holds the exception.
RUN_FAILED = "failed"
#: Method status recorded when an estimator raised instead of returning a status.
METHOD_ERROR = "error"

#: Columns of the per-run x method table, in order (units in the names).
CSV_COLUMNS = (
    "run_id",
    "index",
    "case",
    "x_c_true_m",
    "repeat",
    "seed",
    "run_status",
    "method",
    "status",
    "reason",
    "x_c_estimate_m",
    "error_m",
    "abs_error_m",
    "omega1_rad_s",
    "peak_quality",
    "ratio_estimate_m",
    "candidates_m",
    "t_c_s",
    "t_1_s",
    "t_e_s",
    "interval_low_m",
    "interval_high_m",
    "simulate_s",
    "estimate_s",
    "noise_scale",
    "x_c_contact_m",
    "error_contact_m",
    "abs_error_contact_m",
    "omega1_se_rad_s",
    "omega1_crb_rad_s",
)

_FLOAT_FIELDS = ("x_c", "omega1", "peak_quality", "ratio_estimate", "t_c", "t_1", "t_e")


def float_or_nan(value: Any) -> float:
    """A stored value (JSON number or null, CSV text) as a float, NaN when missing or not a number.

    Parameters
    ----------
    value : Any
        ``None``, ``""``, a number or its text (``"0.5"``, ``"nan"``, ``"inf"``), or anything else.

    Returns
    -------
    float
        ``float(value)``, or NaN when ``float`` cannot convert it.
    """
    try:
        return float(value)
    except (TypeError, ValueError):  # None, "", "n/a", a list...
        return math.nan


def _interval(diagnostics: Any) -> tuple[float, float]:
    """(low, high) of ``diagnostics["interval"]`` in m, or (NaN, NaN) when absent or malformed."""
    if not isinstance(diagnostics, Mapping):
        return math.nan, math.nan
    value: Any = diagnostics.get("interval")
    try:
        low, high = (float(v) for v in value)
    except (TypeError, ValueError):
        return math.nan, math.nan
    return low, high


def _diagnostic(diagnostics: Any, key: str) -> float:
    """``diagnostics[key]`` as a float, NaN when absent or not a number."""
    if not isinstance(diagnostics, Mapping):
        return math.nan
    return float_or_nan(diagnostics.get(key))


def _status_text(status: Any) -> str:
    value = getattr(status, "value", status)
    return str(value)


@dataclass(frozen=True)
class MethodOutcome:
    """One method's estimate from one recording.

    Parameters
    ----------
    method : str
        Estimation method name.
    status : str
        The estimator's status (e.g. ``"ok"``), or ``"error"`` when it raised.
    reason : str
        The estimator's reason, or the exception text.
    x_c : float
        Estimated contact point (m); NaN when none.
    omega1 : float
        Measured fundamental frequency (rad/s); NaN when the method does not measure it.
    peak_quality : float
        Spectral peak power over the band's median power (dimensionless); NaN when not measured.
    ratio_estimate : float
        Torque/force ratio estimate of Eq. 21 (m); NaN when not used.
    candidates : tuple of float
        Contact points consistent with the measured frequency (m).
    t_c, t_1, t_e : float
        Contact instant, push instant and end of estimation (s); NaN when not available.
    elapsed_s : float
        Wall-clock time of this estimate (s).
    interval_low, interval_high : float
        Bounds of the method's 95 % interval of x_c (m), for methods that give one (``fast``);
        NaN otherwise.
    omega1_se : float
        The method's reported standard error of omega_1 (rad/s, ``diagnostics["omega1_se"]``);
        NaN for methods that report none.
    omega1_crb : float
        Cramer-Rao bound of omega_1 for the method's own fit (rad/s,
        ``diagnostics["omega1_crb"]``); NaN for methods that report none.
    """

    method: str
    status: str
    reason: str = ""
    x_c: float = math.nan
    omega1: float = math.nan
    peak_quality: float = math.nan
    ratio_estimate: float = math.nan
    candidates: tuple[float, ...] = ()
    t_c: float = math.nan
    t_1: float = math.nan
    t_e: float = math.nan
    elapsed_s: float = math.nan
    interval_low: float = math.nan
    interval_high: float = math.nan
    omega1_se: float = math.nan
    omega1_crb: float = math.nan

    @classmethod
    def from_estimate(cls, method: str, estimate: Any, elapsed_s: float) -> MethodOutcome:
        """Copy the fields of an estimation result (``ContactEstimate``) that tables need.

        Fields a method does not have are NaN; an interval (a pair of lengths in m) is read from
        the result's ``interval`` or, failing that, ``diagnostics["interval"]``; the standard
        error and Cramer-Rao bound of omega_1 from ``diagnostics["omega1_se"]`` and
        ``diagnostics["omega1_crb"]``.
        """
        diagnostics = getattr(estimate, "diagnostics", None)
        values = {name: float_or_nan(getattr(estimate, name, None)) for name in _FLOAT_FIELDS}
        candidates = getattr(estimate, "candidates", None)
        low, high = _interval({"interval": getattr(estimate, "interval", None)})
        if math.isnan(low):
            low, high = _interval(diagnostics)
        return cls(
            method=method,
            status=_status_text(getattr(estimate, "status", "unknown")),
            reason=str(getattr(estimate, "reason", "") or ""),
            candidates=tuple(
                float_or_nan(c) for c in (candidates if candidates is not None else ())
            ),
            elapsed_s=float(elapsed_s),
            interval_low=low,
            interval_high=high,
            omega1_se=_diagnostic(diagnostics, "omega1_se"),
            omega1_crb=_diagnostic(diagnostics, "omega1_crb"),
            **values,
        )

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict; NaN is stored as null."""
        return {
            "method": self.method,
            "status": self.status,
            "reason": self.reason,
            **{name: _json_float(getattr(self, name)) for name in _FLOAT_FIELDS},
            "candidates": [_json_float(c) for c in self.candidates],
            "elapsed_s": _json_float(self.elapsed_s),
            "interval": [_json_float(self.interval_low), _json_float(self.interval_high)],
            "omega1_se": _json_float(self.omega1_se),
            "omega1_crb": _json_float(self.omega1_crb),
        }

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> MethodOutcome:
        """Inverse of :meth:`to_dict`."""
        return cls(
            method=str(data["method"]),
            status=str(data["status"]),
            reason=str(data.get("reason", "")),
            candidates=tuple(float_or_nan(c) for c in data.get("candidates", [])),
            elapsed_s=float_or_nan(data.get("elapsed_s")),
            interval_low=_interval({"interval": data.get("interval")})[0],
            interval_high=_interval({"interval": data.get("interval")})[1],
            omega1_se=float_or_nan(data.get("omega1_se")),
            omega1_crb=float_or_nan(data.get("omega1_crb")),
            **{name: float_or_nan(data.get(name)) for name in _FLOAT_FIELDS},
        )


@dataclass(frozen=True)
class RunResult:
    """The outcome of one run: the run's identity, its status and every method's estimate.

    Parameters
    ----------
    run_id, index, case, contact_point, repeat, seed
        Copied from the :class:`~sensing_antenna.campaign.runs.RunSpec` (SI units).
    status : str
        :data:`RUN_OK` or :data:`RUN_FAILED`.
    error : str
        Exception type and message when the run failed, else empty.
    detail : str
        Traceback of a failed run, else empty.
    simulate_s : float
        Wall-clock time spent producing the recording (s).
    methods : tuple of MethodOutcome
        One entry per estimation method.
    contact_abscissa : float
        Where the link actually touched (m): the simulator's ground truth ``true_xc``, the
        contact abscissa along the link at the last in-contact sample (it sits a little nearer
        the base than the nominal ``contact_point``). NaN when unknown (no contact, or a run
        stored before this field existed).
    noise_scale : float
        Sensor noise level of the run (``Scenario.noise_scale``); NaN for a run stored before
        this field existed (those are all at the campaign's main level).
    """

    run_id: str
    index: int
    case: str
    contact_point: float
    repeat: int
    seed: int
    status: str
    error: str = ""
    detail: str = ""
    simulate_s: float = math.nan
    methods: tuple[MethodOutcome, ...] = field(default=())
    contact_abscissa: float = math.nan
    noise_scale: float = math.nan

    @classmethod
    def failed(cls, run: RunSpec, error: str, detail: str = "") -> RunResult:
        """A result recording that ``run`` raised ``error``."""
        return cls(
            run_id=run.run_id,
            index=run.index,
            case=run.case,
            contact_point=run.contact_point,
            repeat=run.repeat,
            seed=run.seed,
            status=RUN_FAILED,
            error=error,
            detail=detail,
            noise_scale=run.noise_scale,
        )

    @classmethod
    def for_run(
        cls,
        run: RunSpec,
        methods: Sequence[MethodOutcome],
        simulate_s: float,
        contact_abscissa: float = math.nan,
    ) -> RunResult:
        """A successful result for ``run``; ``contact_abscissa`` is the recording's true x_c."""
        return cls(
            run_id=run.run_id,
            index=run.index,
            case=run.case,
            contact_point=run.contact_point,
            repeat=run.repeat,
            seed=run.seed,
            status=RUN_OK,
            simulate_s=float(simulate_s),
            methods=tuple(methods),
            contact_abscissa=float(contact_abscissa),
            noise_scale=run.noise_scale,
        )

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict."""
        return {
            "run_id": self.run_id,
            "index": self.index,
            "case": self.case,
            "contact_point": self.contact_point,
            "repeat": self.repeat,
            "seed": self.seed,
            "status": self.status,
            "error": self.error,
            "detail": self.detail,
            "simulate_s": _json_float(self.simulate_s),
            "methods": [m.to_dict() for m in self.methods],
            "contact_abscissa": _json_float(self.contact_abscissa),
            "noise_scale": _json_float(self.noise_scale),
        }

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> RunResult:
        """Inverse of :meth:`to_dict`; raises KeyError or TypeError on malformed data.

        Runs stored before ``contact_abscissa`` and ``noise_scale`` existed read them as NaN.
        """
        return cls(
            run_id=str(data["run_id"]),
            index=int(data["index"]),
            case=str(data["case"]),
            contact_point=float(data["contact_point"]),
            repeat=int(data["repeat"]),
            seed=int(data["seed"]),
            status=str(data["status"]),
            error=str(data.get("error", "")),
            detail=str(data.get("detail", "")),
            simulate_s=float_or_nan(data.get("simulate_s")),
            methods=tuple(MethodOutcome.from_dict(m) for m in data.get("methods", [])),
            contact_abscissa=float_or_nan(data.get("contact_abscissa")),
            noise_scale=float_or_nan(data.get("noise_scale")),
        )


def result_rows(result: RunResult, methods: Sequence[str]) -> list[dict[str, Any]]:
    """Rows of the run x method table (:data:`CSV_COLUMNS`) for one run.

    A failed run gives one row per expected method with status ``run-failed`` and the error as
    reason, so every run x method appears in the table. ``error_m`` is against the nominal x_c
    (as in the paper's tables), ``error_contact_m`` against the contact abscissa.
    """
    base = {
        "run_id": result.run_id,
        "index": result.index,
        "case": result.case,
        "x_c_true_m": result.contact_point,
        "repeat": result.repeat,
        "seed": result.seed,
        "run_status": result.status,
        "simulate_s": result.simulate_s,
        "noise_scale": result.noise_scale,
        "x_c_contact_m": result.contact_abscissa,
    }
    by_method = {m.method: m for m in result.methods}
    rows = []
    for method in methods:
        outcome = by_method.get(method)
        if outcome is None:
            reason = result.error if result.status == RUN_FAILED else "method not run"
            outcome = MethodOutcome(method=method, status="run-failed", reason=reason)
        error = outcome.x_c - result.contact_point
        error_contact = outcome.x_c - result.contact_abscissa
        rows.append(
            {
                **base,
                "method": method,
                "status": outcome.status,
                "reason": outcome.reason,
                "x_c_estimate_m": outcome.x_c,
                "error_m": error,
                "abs_error_m": abs(error),
                "omega1_rad_s": outcome.omega1,
                "peak_quality": outcome.peak_quality,
                "ratio_estimate_m": outcome.ratio_estimate,
                "candidates_m": ";".join(f"{c:.6g}" for c in outcome.candidates),
                "t_c_s": outcome.t_c,
                "t_1_s": outcome.t_1,
                "t_e_s": outcome.t_e,
                "interval_low_m": outcome.interval_low,
                "interval_high_m": outcome.interval_high,
                "estimate_s": outcome.elapsed_s,
                "error_contact_m": error_contact,
                "abs_error_contact_m": abs(error_contact),
                "omega1_se_rad_s": outcome.omega1_se,
                "omega1_crb_rad_s": outcome.omega1_crb,
            }
        )
    return rows


def _json_float(value: float) -> float | None:
    return None if value is None or not math.isfinite(value) else float(value)
