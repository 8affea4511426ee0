"""The on-disk layout of a campaign, written so that an interrupted campaign can resume.

::

    OUT/
      campaign.json        the spec and its fingerprint (a resume must use the same spec)
      antenna.toml         the model every estimator used (identified observer, calibrated T_e)
      device.toml          the simulated hardware (with the observer its controller used)
      calibration.json     the T_e calibration of Section 5.1, when the spec asks for it
      second_device/       antenna.toml, device.toml, calibration.json of the second device's
                           own preparation, when the spec has one
      runs/<run_id>.json   one file per finished run, written atomically (temp file + os.replace)
      runs.csv             every run x method, rebuilt from runs/ (SI units)
      report.md, figures/  written by :mod:`sensing_antenna.campaign.report`
      .lock                held (``flock``) by the campaign running here, with its pid

A run file either exists complete or not at all, so killing the campaign at any moment loses at
most the runs in progress; they are redone on the next start. The preparation (observer
identification, calibration) is written before any run, ``antenna.toml`` last, so its presence
means the preparation is complete; ``calibration.json`` carries the fingerprint of the spec parts
it depends on and is redone when they differ. One campaign at a time runs in a directory
(:func:`campaign_lock`); the temp files of writers that are gone are removed when it starts. Run
files of runs the spec does not have are left out (:func:`load_campaign_results`).
"""

from __future__ import annotations

import contextlib
import csv
import json
import os
import socket
import time
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path

from sensing_antenna.antenna import Antenna, antenna_to_toml, load_antenna
from sensing_antenna.calibration.frequency import FrequencyCalibration
from sensing_antenna.campaign.parsing import parse_campaign_spec
from sensing_antenna.campaign.records import CSV_COLUMNS, RUN_FILE_FORMAT, CampaignRow, RunResult
from sensing_antenna.campaign.runs import run_ids
from sensing_antenna.campaign.schema import CampaignSpec
from sensing_antenna.errors import SensingAntennaError

__all__ = [
    "ANTENNA_FILE",
    "CALIBRATION_FILE",
    "CSV_FILE",
    "DEVICE_FILE",
    "LOCK_FILE",
    "MANIFEST_FILE",
    "RUNS_DIR",
    "SECOND_DEVICE_DIR",
    "CampaignStoreError",
    "Preparation",
    "StoredRuns",
    "atomic_write_text",
    "campaign_lock",
    "load_campaign_results",
    "load_run_results",
    "read_calibration",
    "read_manifest",
    "read_preparation",
    "read_runs_csv",
    "read_stored_antenna",
    "read_stored_device",
    "remove_stale_temp_files",
    "write_manifest",
    "write_preparation",
    "write_run_result",
    "write_runs_csv",
    "write_stored_antenna",
]

MANIFEST_FILE = "campaign.json"
ANTENNA_FILE = "antenna.toml"
DEVICE_FILE = "device.toml"
CALIBRATION_FILE = "calibration.json"
RUNS_DIR = "runs"
#: Subdirectory holding the second device's preparation (the layout of the main one).
SECOND_DEVICE_DIR = "second_device"
CSV_FILE = "runs.csv"
LOCK_FILE = ".lock"


class CampaignStoreError(SensingAntennaError, ValueError):
    """A campaign directory that cannot be used: wrong spec, damaged run file, missing files."""


@contextlib.contextmanager
def campaign_lock(out_dir: Path) -> Iterator[None]:
    """Hold ``out_dir`` for this campaign: another campaign on it is refused while inside.

    An exclusive ``flock`` on ``out_dir/.lock``, which also records the holder's pid, host and
    start time for the message. The kernel releases the lock when the holder's process (and any
    worker process it forked) ends, however it ends, so a lock file left by a killed campaign
    is no lock: there is no stale lock to detect. On a system without ``fcntl`` (Windows) the
    directory is not locked.

    Raises
    ------
    CampaignStoreError
        Naming the directory and the process that holds it.
    """
    try:
        import fcntl
    except ImportError:  # pragma: no cover - not POSIX
        yield
        return
    path = out_dir / LOCK_FILE
    handle = open(path, "a+", encoding="utf-8")
    try:
        try:
            fcntl.flock(handle.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            handle.seek(0)
            holder = handle.read().strip() or "another process"
            raise CampaignStoreError(
                f"{out_dir}: in use by another campaign ({holder}); wait for it to end, or use "
                "another output directory"
            ) from None
        handle.seek(0)
        handle.truncate()
        started = time.strftime("%Y-%m-%d %H:%M:%S")
        handle.write(f"process {os.getpid()} on {socket.gethostname()}, started {started}\n")
        handle.flush()
        try:
            yield
        finally:
            # explicitly: a worker process forked meanwhile shares the lock until it exits
            fcntl.flock(handle.fileno(), fcntl.LOCK_UN)
    finally:
        handle.close()


def remove_stale_temp_files(out_dir: Path) -> list[Path]:
    """Remove the temp files (``.<name>.<pid>.tmp``) whose writing process is gone.

    Run under :func:`campaign_lock`; a temp file of a live process (a ``campaign report``
    rebuilding ``runs.csv`` meanwhile) is left alone. Returns the files removed.
    """
    removed = []
    for folder in (out_dir, out_dir / RUNS_DIR):
        if not folder.is_dir():
            continue
        for path in folder.glob(".*.tmp"):
            pid = path.name[: -len(".tmp")].rsplit(".", 1)[-1]
            if not pid.isdigit() or (int(pid) != os.getpid() and _process_exists(int(pid))):
                continue
            path.unlink(missing_ok=True)
            removed.append(path)
    return removed


def _process_exists(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # exists, owned by someone else
        return True
    except OverflowError:  # not a pid at all
        return False
    return True


def atomic_write_text(path: Path, text: str) -> None:
    """Write ``text`` to ``path``: readers see either the old file or the complete new one."""
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    with open(tmp, "w", encoding="utf-8") as handle:
        handle.write(text)
        handle.flush()
        os.fsync(handle.fileno())
    os.replace(tmp, path)


def write_manifest(out_dir: Path, spec: CampaignSpec) -> None:
    """Record the spec in ``out_dir``; refuse a directory holding a preparation or runs of a
    different spec (a manifest alone, left by a campaign stopped before its preparation, is
    replaced)."""
    path = out_dir / MANIFEST_FILE
    if path.is_file():
        stored = read_manifest(out_dir)
        if stored.fingerprint() == spec.fingerprint():
            return
        if _holds_work(out_dir):
            old, new = stored.determining(), spec.determining()
            fields = sorted(k for k in {*old, *new} if old.get(k) != new.get(k))
            differs = f"; it differs in {', '.join(fields)}" if fields else ""
            raise CampaignStoreError(
                f"{path}: fingerprint: the preparation and runs stored here come from a "
                f"different campaign spec ({stored.name!r}{differs}); use another output "
                "directory"
            )
    data = {"fingerprint": spec.fingerprint(), "spec": spec.to_dict(), "source": spec.source}
    atomic_write_text(path, json.dumps(data, indent=2, sort_keys=True) + "\n")


def _holds_work(out_dir: Path) -> bool:
    """Whether ``out_dir`` holds anything a campaign made besides its manifest."""
    made = (ANTENNA_FILE, DEVICE_FILE, CALIBRATION_FILE, RUNS_DIR, SECOND_DEVICE_DIR, CSV_FILE)
    return any((out_dir / name).exists() for name in made)


def read_manifest(out_dir: Path) -> CampaignSpec:
    """The spec stored in ``out_dir/campaign.json``."""
    path = out_dir / MANIFEST_FILE
    if not path.is_file():
        raise CampaignStoreError(f"{path}: no such file; is {out_dir} a campaign directory?")
    try:
        data = json.loads(path.read_text("utf-8"))
        spec_data = data["spec"]
    except (json.JSONDecodeError, KeyError, TypeError) as exc:
        raise CampaignStoreError(f"{path}: spec: damaged manifest ({exc})") from exc
    return parse_campaign_spec(spec_data, str(path))


@dataclass(frozen=True)
class Preparation:
    """What the steps before the runs produce: the two antennas and the calibration.

    Attributes
    ----------
    model : Antenna
        What the estimators use: the nominal model with the identified observer and, after a
        calibration, T_e.
    device : Antenna
        The simulated hardware, with the observer its controller (the stop rule) uses.
    calibration : FrequencyCalibration or None
        The T_e fit of Section 5.1, when the spec asks for it.
    """

    model: Antenna
    device: Antenna
    calibration: FrequencyCalibration | None = None

    @classmethod
    def same(cls, antenna: Antenna) -> Preparation:
        """Device and model are the same antenna, no calibration."""
        return cls(model=antenna, device=antenna)


def write_preparation(out_dir: Path, spec: CampaignSpec, preparation: Preparation) -> None:
    """Store the preparation; ``antenna.toml`` last, so that it marks a complete preparation."""
    if preparation.calibration is not None:
        data = {
            "fingerprint": spec.preparation_fingerprint(),
            "calibration": preparation.calibration.to_dict(),
        }
        text = json.dumps(data, indent=1, allow_nan=False) + "\n"
        atomic_write_text(out_dir / CALIBRATION_FILE, text)
    atomic_write_text(out_dir / DEVICE_FILE, antenna_to_toml(preparation.device))
    write_stored_antenna(out_dir, preparation.model)


def read_calibration(out_dir: Path) -> tuple[str, FrequencyCalibration] | None:
    """The stored calibration and the fingerprint it was made for, or None if there is none."""
    path = out_dir / CALIBRATION_FILE
    if not path.is_file():
        return None
    try:
        data = json.loads(path.read_text("utf-8"))
        return str(data["fingerprint"]), FrequencyCalibration.from_dict(data["calibration"])
    except (json.JSONDecodeError, KeyError, TypeError, ValueError) as exc:
        raise CampaignStoreError(
            f"{path}: calibration: damaged file ({exc}); delete it to redo the calibration"
        ) from exc


def read_preparation(out_dir: Path, spec: CampaignSpec) -> Preparation | None:
    """The preparation stored by an earlier start for this spec, or None if it must be made.

    None when ``antenna.toml`` is missing, or when the spec asks for a calibration and
    ``calibration.json`` is missing or was made for other settings. A directory without
    ``device.toml`` simulated with the model antenna.
    """
    model = read_stored_antenna(out_dir)
    if model is None:
        return None
    calibration = None
    if spec.calibration.enabled:
        stored = read_calibration(out_dir)
        if stored is None or stored[0] != spec.preparation_fingerprint():
            return None
        calibration = stored[1]
    device = read_stored_device(out_dir) or model
    return Preparation(model=model, device=device, calibration=calibration)


def write_stored_antenna(out_dir: Path, antenna: Antenna) -> None:
    """Save the antenna the runs use, atomically."""
    atomic_write_text(out_dir / ANTENNA_FILE, antenna_to_toml(antenna))


def read_stored_antenna(out_dir: Path) -> Antenna | None:
    """The model stored by an earlier start, or None."""
    path = out_dir / ANTENNA_FILE
    return load_antenna(path) if path.is_file() else None


def read_stored_device(out_dir: Path) -> Antenna | None:
    """The simulated hardware stored by an earlier start, or None."""
    path = out_dir / DEVICE_FILE
    return load_antenna(path) if path.is_file() else None


def write_run_result(out_dir: Path, result: RunResult) -> Path:
    """Store one finished run as ``runs/<run_id>.json`` (atomic)."""
    runs = out_dir / RUNS_DIR
    runs.mkdir(parents=True, exist_ok=True)
    path = runs / f"{result.run_id}.json"
    atomic_write_text(path, json.dumps(result.to_dict(), indent=1, allow_nan=False) + "\n")
    return path


def load_run_results(out_dir: Path, methods: Sequence[str]) -> dict[str, RunResult]:
    """Every finished run stored in ``out_dir/runs``, keyed by run id (temp files ignored).

    ``methods`` are the campaign's (the spec's): run files of format 1 hold no row for a
    method of a failed run, and get one (see :meth:`RunResult.from_dict`).
    """
    runs = out_dir / RUNS_DIR
    results: dict[str, RunResult] = {}
    if not runs.is_dir():
        return results
    for path in sorted(runs.glob("*.json")):
        try:
            data = json.loads(path.read_text("utf-8"))
            if isinstance(data, dict) and data.get("format", 1) not in (1, 2, RUN_FILE_FORMAT):
                raise CampaignStoreError(
                    f"{path}: format: {data['format']!r} is not one this version reads (1 to "
                    f"{RUN_FILE_FORMAT}); use the version of sensing-antenna that wrote it"
                )
            result = RunResult.from_dict(data, methods)
        except CampaignStoreError:
            raise
        except (json.JSONDecodeError, KeyError, TypeError, ValueError) as exc:
            raise CampaignStoreError(
                f"{path}: damaged run file ({exc}); delete it to redo that run"
            ) from exc
        if result.run_id != path.stem:
            raise CampaignStoreError(f"{path}: run_id: file holds run {result.run_id!r}")
        results[result.run_id] = result
    return results


@dataclass(frozen=True)
class StoredRuns:
    """The stored runs of a campaign directory that belong to its spec.

    Attributes
    ----------
    results : dict of str to RunResult
        By run id, only runs of the spec.
    foreign : tuple of str
        Ids of valid run files in ``runs/`` that are not runs of the spec (copied in, or left
        by hand): left out of ``runs.csv`` and the report, which say so.
    """

    results: dict[str, RunResult]
    foreign: tuple[str, ...] = ()


def load_campaign_results(out_dir: Path, spec: CampaignSpec) -> StoredRuns:
    """The stored runs of ``spec`` in ``out_dir``, and the ids of run files it does not have."""
    stored = load_run_results(out_dir, spec.methods)
    ids = set(run_ids(spec))
    foreign = tuple(sorted(k for k in stored if k not in ids))
    return StoredRuns({k: v for k, v in stored.items() if k in ids}, foreign)


def write_runs_csv(path: Path, results: Iterable[RunResult]) -> Path:
    """Write every run's rows, by run index, as runs.csv (:data:`~.records.CSV_COLUMNS`)."""
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    with open(tmp, "w", encoding="utf-8", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(CSV_COLUMNS), lineterminator="\n")
        writer.writeheader()
        for result in sorted(results, key=lambda r: r.index):
            writer.writerows(row.to_csv() for row in result.rows)
    os.replace(tmp, path)
    return path


def read_runs_csv(path: Path) -> list[CampaignRow]:
    """The rows of a runs.csv, as written (candidates to 6 significant digits).

    Raises
    ------
    CampaignStoreError
        Naming the file and line of a row that cannot be read.
    """
    try:
        with open(path, encoding="utf-8", newline="") as handle:
            reader = csv.DictReader(handle)
            rows = []
            for record in reader:
                try:
                    rows.append(CampaignRow.from_csv(record))
                except (KeyError, TypeError, ValueError) as exc:
                    raise CampaignStoreError(
                        f"{path}: line {reader.line_num}: cannot be read ({exc})"
                    ) from exc
    except OSError as exc:
        raise CampaignStoreError(f"{path}: cannot be read ({exc.strerror or exc})") from exc
    return rows
