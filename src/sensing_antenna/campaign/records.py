"""What a campaign records: one typed row per run x method, and one run's rows together.

:class:`CampaignRow` is the one shape an estimate takes in a campaign: built from one method's
``ContactEstimate`` on one run, stored in the run's file (:class:`RunResult`), written as one line
of ``runs.csv`` (its fields are the columns, in order: :data:`CSV_COLUMNS`) and read back, from
either, as the same rows the tables compute from. All values SI, units in the field names.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, fields, replace
from typing import TYPE_CHECKING, Any

from sensing_antenna.campaign.runs import RunSpec

if TYPE_CHECKING:
    from sensing_antenna.estimation.result import ContactEstimate

__all__ = [
    "CSV_COLUMNS",
    "METHOD_ERROR",
    "METHOD_RUN_FAILED",
    "RUN_FAILED",
    "RUN_FILE_FORMAT",
    "RUN_OK",
    "CampaignRow",
    "RunResult",
    "float_or_nan",
]

#: Run status: the run function returned.
RUN_OK = "ok"
#: Run status: the run function raised; every row of the run has method status ``run-failed``.
RUN_FAILED = "failed"
#: Method status of a failed run's rows.
METHOD_RUN_FAILED = "run-failed"
#: Method status recorded when an estimator raised instead of returning a status.
METHOD_ERROR = "error"
#: Layout of the run files this code writes (see :meth:`RunResult.to_dict`): 3 measures
#: ``point_error_m`` against the contact at the estimate's instant (the versions writing 2
#: mostly did against the end of the record; the rows otherwise alike).
RUN_FILE_FORMAT = 3


def float_or_nan(value: Any) -> float:
    """A stored value (JSON number or null, CSV text) as a float; NaN when missing or not finite.

    Parameters
    ----------
    value : Any
        ``None``, ``""``, a number or its text (``"0.5"``, ``"nan"``), or anything else.

    Returns
    -------
    float
        ``float(value)`` when finite, else :data:`math.nan` (the one NaN object, so rows holding
        it compare equal).
    """
    try:
        number = float(value)
    except (TypeError, ValueError):  # None, "", "n/a", a list...
        return math.nan
    return number if math.isfinite(number) else math.nan


@dataclass(frozen=True)
class CampaignRow:
    """One method's estimate on one run, beside the run's truth (SI units, in the names).

    Non-finite numbers are stored as NaN, meaning "no value". Fields ``error_m``,
    ``abs_error_m``, ``error_contact_m`` and ``abs_error_contact_m`` are computed from the others.

    Attributes
    ----------
    run_id, index, case, repeat, seed : str, int, str, int, int
        The run (:class:`~sensing_antenna.campaign.runs.RunSpec`).
    x_c_true_m : float
        Nominal contact point of the spec (m): where the undeflected link meets the obstacle.
    run_status : str
        ``ok`` or ``failed`` (the simulation raised).
    method, status, reason : str
        The method, its status (a ``Status`` value, ``error`` when it raised, ``run-failed``)
        and its reason ("" when ok).
    x_c_estimate_m : float
        Estimated contact point (m).
    error_m, abs_error_m : float
        Estimate - nominal x_c and its magnitude (m), as in the paper's tables.
    omega1_rad_s, peak_quality : float
        Measured fundamental (rad/s) and its peak-to-median power ratio.
    ratio_estimate_m : float
        Estimator 2's torque/force ratio estimate (m).
    candidates_m : tuple of float
        Contact points consistent with omega_1 (m); runs.csv holds them to 6 significant digits.
    t_c_s, t_1_s, t_e_s : float
        Contact instant, push instant, instant the estimate was available (s).
    interval_low_m, interval_high_m : float
        The method's 95 % interval of x_c (m), for methods that give one.
    simulate_s : float
        Wall-clock time to simulate the recording (s), the same on every row of a run.
    estimate_s : float
        Wall-clock time to estimate the recording with this method alone (s): the front end's
        ``front_end_s`` plus this method's conclusion.
    noise_scale : float
        Sensor noise level of the run (multiple of the simulator's nominal noise).
    x_c_contact_m : float
        Where the link touched (m): the simulator's contact abscissa ``true_xc``.
    error_contact_m, abs_error_contact_m : float
        Estimate - contact abscissa and its magnitude (m).
    omega1_se_rad_s, omega1_crb_rad_s : float
        The method's standard error and Cramer-Rao bound of omega_1 (rad/s), when reported.
    front_end_s : float
        Wall-clock time of the estimation front end on the recording (s), run once per run and
        shared by its methods; ``estimate_s - front_end_s`` is the method's own time (the
        first method to read what the evidence computes once pays for it).
    point_error_m : float
        Distance (m) from the estimate's touched point in 3D, on the link's surface (its
        ``contact_point``, absolute frame, moved by ``mapping.points.surface_offset``), to where
        the link touched at the instant the point describes (the recording's contact track at
        the estimate's ``diagnostics["t_point"]``, ``recording.tracked_contact``).
    bound_delay_s : float
        ``fast`` only: the information bound of t_e - t_1 (s), the first window from t_1 whose
        95 % interval would be within the tolerance with omega_1 at its Cramer-Rao bound and no
        floors (``estimation.methods.fast.bound_delay``); NaN when no window qualifies before
        the cap, when not computed (``CampaignSpec.fast_bound``) and for other methods.
    """

    run_id: str
    index: int
    case: str
    x_c_true_m: float
    repeat: int
    seed: int
    run_status: str
    method: str
    status: str
    reason: str = ""
    x_c_estimate_m: float = math.nan
    error_m: float = field(init=False)
    abs_error_m: float = field(init=False)
    omega1_rad_s: float = math.nan
    peak_quality: float = math.nan
    ratio_estimate_m: float = math.nan
    candidates_m: tuple[float, ...] = ()
    t_c_s: float = math.nan
    t_1_s: float = math.nan
    t_e_s: float = math.nan
    interval_low_m: float = math.nan
    interval_high_m: float = math.nan
    simulate_s: float = math.nan
    estimate_s: float = math.nan
    noise_scale: float = math.nan
    x_c_contact_m: float = math.nan
    error_contact_m: float = field(init=False)
    abs_error_contact_m: float = field(init=False)
    omega1_se_rad_s: float = math.nan
    omega1_crb_rad_s: float = math.nan
    front_end_s: float = math.nan
    point_error_m: float = math.nan
    bound_delay_s: float = math.nan

    def __post_init__(self) -> None:
        for f in fields(self):
            if not f.init:
                continue
            value = getattr(self, f.name)
            if f.type == "float":
                object.__setattr__(self, f.name, float_or_nan(value))
            elif f.type == "int":
                object.__setattr__(self, f.name, int(value))
            elif f.type == "str":
                object.__setattr__(self, f.name, str(value))
        candidates = tuple(float_or_nan(c) for c in self.candidates_m)
        object.__setattr__(self, "candidates_m", candidates)
        error = float_or_nan(self.x_c_estimate_m - self.x_c_true_m)
        contact = float_or_nan(self.x_c_estimate_m - self.x_c_contact_m)
        object.__setattr__(self, "error_m", error)
        object.__setattr__(self, "abs_error_m", float_or_nan(abs(error)))
        object.__setattr__(self, "error_contact_m", contact)
        object.__setattr__(self, "abs_error_contact_m", float_or_nan(abs(contact)))

    @property
    def delay_s(self) -> float:
        """t_e - t_1 (s): how long after the push the estimate was available; NaN if unknown."""
        return float_or_nan(self.t_e_s - self.t_1_s)

    @property
    def truth_m(self) -> float:
        """Where the link touched (m): the contact abscissa, or the nominal x_c when unknown."""
        return self.x_c_contact_m if math.isfinite(self.x_c_contact_m) else self.x_c_true_m

    @classmethod
    def of_estimate(
        cls,
        run: RunSpec,
        estimate: ContactEstimate,
        *,
        contact_abscissa: float = math.nan,
        simulate_s: float = math.nan,
        front_end_s: float = math.nan,
        estimate_s: float = math.nan,
        point_error_m: float = math.nan,
        bound_delay_s: float = math.nan,
    ) -> CampaignRow:
        """The row of one method's estimate on ``run`` (the method named by the estimate).

        The standard error and Cramer-Rao bound of omega_1 come from the estimate's
        ``diagnostics["omega1_se"]`` and ``diagnostics["omega1_crb"]`` (``fast``);
        ``point_error_m`` the touched point's error in 3D (m), if known;
        ``bound_delay_s`` the information bound of the delay (s, ``fast``).
        """
        low, high = estimate.interval if estimate.interval is not None else (math.nan, math.nan)
        diagnostics = estimate.diagnostics
        return cls(
            **_run_fields(run, RUN_OK, contact_abscissa, simulate_s, front_end_s),
            method=estimate.method,
            status=estimate.status.value,
            reason=estimate.reason or "",
            x_c_estimate_m=estimate.x_c,
            omega1_rad_s=estimate.omega1,
            peak_quality=estimate.peak_quality,
            ratio_estimate_m=estimate.ratio_estimate,
            candidates_m=tuple(estimate.candidates),
            t_c_s=estimate.t_c,
            t_1_s=estimate.t_1,
            t_e_s=estimate.t_e,
            interval_low_m=low,
            interval_high_m=high,
            estimate_s=estimate_s,
            omega1_se_rad_s=float_or_nan(diagnostics.get("omega1_se")),
            omega1_crb_rad_s=float_or_nan(diagnostics.get("omega1_crb")),
            point_error_m=point_error_m,
            bound_delay_s=bound_delay_s,
        )

    @classmethod
    def of_error(
        cls,
        run: RunSpec,
        method: str,
        reason: str,
        *,
        contact_abscissa: float = math.nan,
        simulate_s: float = math.nan,
        front_end_s: float = math.nan,
        estimate_s: float = math.nan,
    ) -> CampaignRow:
        """The row of a method that raised on ``run`` (status :data:`METHOD_ERROR`)."""
        return cls(
            **_run_fields(run, RUN_OK, contact_abscissa, simulate_s, front_end_s),
            method=method,
            status=METHOD_ERROR,
            reason=reason,
            estimate_s=estimate_s,
        )

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict of the stored fields (NaN as null; computed fields left out)."""
        data: dict[str, Any] = {}
        for f in fields(self):
            if f.init:
                value = getattr(self, f.name)
                if isinstance(value, float):
                    value = None if math.isnan(value) else value
                elif isinstance(value, tuple):
                    value = list(value)
                data[f.name] = value
        return data

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> CampaignRow:
        """Inverse of :meth:`to_dict`; raises KeyError, TypeError or ValueError on bad data."""
        values = {f.name: data[f.name] for f in fields(cls) if f.init and f.name in data}
        values["candidates_m"] = tuple(data.get("candidates_m") or ())
        return cls(**values)

    def to_csv(self) -> dict[str, str]:
        """The row as runs.csv cells, one per :data:`CSV_COLUMNS` (NaN as an empty cell)."""
        cells: dict[str, str] = {}
        for f in fields(self):
            value = getattr(self, f.name)
            if isinstance(value, float):
                cells[f.name] = "" if math.isnan(value) else repr(value)
            elif isinstance(value, tuple):
                cells[f.name] = ";".join(f"{c:.6g}" for c in value)
            else:
                cells[f.name] = str(value)
        return cells

    @classmethod
    def from_csv(cls, cells: Mapping[str, str]) -> CampaignRow:
        """Inverse of :meth:`to_csv` (candidates to 6 significant digits); missing cells: NaN."""
        values: dict[str, Any] = {}
        for f in fields(cls):
            if not f.init or f.name not in cells:
                continue
            text = cells[f.name]
            if f.type == "float":
                values[f.name] = float_or_nan(text)
            elif f.name == "candidates_m":
                values[f.name] = tuple(float(c) for c in text.split(";") if c)
            else:
                values[f.name] = text
        return cls(**values)


#: Columns of runs.csv, in order: the fields of :class:`CampaignRow`.
CSV_COLUMNS = tuple(f.name for f in fields(CampaignRow))

#: Fields every row of one run shares.
_RUN_FIELDS = (
    "run_id",
    "index",
    "case",
    "x_c_true_m",
    "repeat",
    "seed",
    "run_status",
    "simulate_s",
    "noise_scale",
    "x_c_contact_m",
    "front_end_s",
)


def _run_fields(
    run: RunSpec, status: str, contact_abscissa: float, simulate_s: float, front_end_s: float
) -> dict[str, Any]:
    return {
        "run_id": run.run_id,
        "index": run.index,
        "case": run.case,
        "x_c_true_m": run.contact_point,
        "repeat": run.repeat,
        "seed": run.seed,
        "run_status": status,
        "simulate_s": simulate_s,
        "noise_scale": run.noise_scale,
        "x_c_contact_m": contact_abscissa,
        "front_end_s": front_end_s,
    }


@dataclass(frozen=True)
class RunResult:
    """One run as stored in ``runs/<run_id>.json``: one row per method of the run, in order.

    Attributes
    ----------
    rows : tuple of CampaignRow
        At least one; all of the same run (same values of the run's fields).
    detail : str
        Traceback of a failed run, else empty.
    """

    rows: tuple[CampaignRow, ...]
    detail: str = ""

    def __post_init__(self) -> None:
        object.__setattr__(self, "rows", tuple(self.rows))
        if not self.rows:
            raise ValueError("a run result needs at least one row")
        first = self.rows[0]
        for row in self.rows[1:]:
            for name in _RUN_FIELDS:
                a, b = getattr(first, name), getattr(row, name)
                if a != b and not (a != a and b != b):  # NaN equals NaN here
                    raise ValueError(f"rows of one run differ in {name}")

    @property
    def run_id(self) -> str:
        """The run's identifier."""
        return self.rows[0].run_id

    @property
    def index(self) -> int:
        """The run's position in the campaign."""
        return self.rows[0].index

    @property
    def seed(self) -> int:
        """The run's simulation seed."""
        return self.rows[0].seed

    @property
    def status(self) -> str:
        """:data:`RUN_OK` or :data:`RUN_FAILED`."""
        return self.rows[0].run_status

    @property
    def error(self) -> str:
        """The exception of a failed run (type and message), else empty."""
        return self.rows[0].reason if self.status == RUN_FAILED else ""

    @property
    def methods(self) -> tuple[str, ...]:
        """The methods of the run's rows, in order."""
        return tuple(row.method for row in self.rows)

    @classmethod
    def failed(cls, run: RunSpec, error: str, detail: str = "") -> RunResult:
        """A result recording that ``run`` raised ``error``: one ``run-failed`` row per method."""
        base = _run_fields(run, RUN_FAILED, math.nan, math.nan, math.nan)
        rows = tuple(
            CampaignRow(**base, method=m, status=METHOD_RUN_FAILED, reason=error)
            for m in run.methods
        )
        return cls(rows=rows, detail=detail)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict: the format, the run id, the traceback and the rows."""
        return {
            "format": RUN_FILE_FORMAT,
            "run_id": self.run_id,
            "detail": self.detail,
            "rows": [row.to_dict() for row in self.rows],
        }

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], methods: Sequence[str]) -> RunResult:
        """Inverse of :meth:`to_dict`; also reads run files of formats 1 and 2.

        Format 2 may hold a ``point_error_m`` measured against where the link rested at the
        record's end, not where it touched at the estimate's instant (a file does not say
        which): it reads NaN, so that a campaign resumed across versions does not summarise
        two measures as one.

        Format 1 stored the run's fields once and one entry per method under ``methods`` (a
        failed run none); its rows are rebuilt for ``methods``, the campaign's methods, as
        format 2 stores them, and fields it lacks (``contact_abscissa``, ``noise_scale``, the
        frequency's standard error and bound, the front end's time) read as NaN.

        Raises
        ------
        KeyError, TypeError, ValueError
            On malformed data.
        """
        if data.get("format", 1) == 1:
            return _from_format_1(data, methods)
        if data["format"] not in (2, RUN_FILE_FORMAT):
            raise ValueError(f"unknown run file format {data['format']!r}")
        rows = tuple(CampaignRow.from_dict(row) for row in data["rows"])
        if data["format"] == 2:
            rows = tuple(replace(row, point_error_m=math.nan) for row in rows)
        return cls(rows=rows, detail=str(data.get("detail", "")))


def _from_format_1(data: Mapping[str, Any], methods: Sequence[str]) -> RunResult:
    status = str(data["status"])
    base: dict[str, Any] = {
        "run_id": str(data["run_id"]),
        "index": int(data["index"]),
        "case": str(data["case"]),
        "x_c_true_m": float(data["contact_point"]),
        "repeat": int(data["repeat"]),
        "seed": int(data["seed"]),
        "run_status": status,
        "simulate_s": data.get("simulate_s"),
        "noise_scale": data.get("noise_scale"),
        "x_c_contact_m": data.get("contact_abscissa"),
    }
    stored = {str(m["method"]): m for m in data.get("methods", [])}
    rows = []
    for method in methods:
        entry = stored.get(method)
        if entry is None:
            reason = str(data.get("error", "")) if status == RUN_FAILED else "method not run"
            rows.append(CampaignRow(**base, method=method, status=METHOD_RUN_FAILED, reason=reason))
            continue
        low, high = [*(entry.get("interval") or ()), None, None][:2]
        rows.append(
            CampaignRow(
                **base,
                method=method,
                status=str(entry["status"]),
                reason=str(entry.get("reason", "")),
                x_c_estimate_m=entry.get("x_c"),
                omega1_rad_s=entry.get("omega1"),
                peak_quality=entry.get("peak_quality"),
                ratio_estimate_m=entry.get("ratio_estimate"),
                candidates_m=tuple(entry.get("candidates") or ()),
                t_c_s=entry.get("t_c"),
                t_1_s=entry.get("t_1"),
                t_e_s=entry.get("t_e"),
                interval_low_m=low,
                interval_high_m=high,
                estimate_s=entry.get("elapsed_s"),
                omega1_se_rad_s=entry.get("omega1_se"),
                omega1_crb_rad_s=entry.get("omega1_crb"),
            )
        )
    return RunResult(rows=tuple(rows), detail=str(data.get("detail", "")))
