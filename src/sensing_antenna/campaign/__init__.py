"""Experiment campaigns: declarative specs, parallel runs, typed rows, tables, reports (Section 5).

Modules, in the order a campaign goes through them:

- :mod:`.schema` (the spec as frozen dataclasses) with :mod:`.limits` (its size limits),
  :mod:`.parsing` (TOML files to specs), :mod:`.runs` (seeds and the runs of a spec);
- :mod:`.simulated` (the preparation steps and the run function: simulate, then estimate),
  :mod:`.runner` (parallel, resumable execution) with :mod:`.pool` (the local worker
  processes) and :mod:`.progress` (what it tells the person waiting), :mod:`.store` (the
  campaign directory);
- :mod:`.records` (:class:`CampaignRow`, one run x method, from estimate to file to table);
- :mod:`.tables`, :mod:`.targets` and :mod:`.devices` (statistics of the rows; two devices
  side by side), :mod:`.summary` (every number the report shows), :mod:`.report` with
  :mod:`.report_sections`, :mod:`.report_devices` and :mod:`.figures` (the report, formatting
  only).

The names below are imported lazily, so ``import sensing_antenna.campaign`` stays cheap.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from sensing_antenna.campaign.parsing import (
        default_campaign_spec,
        load_campaign_spec,
        parse_campaign_spec,
    )
    from sensing_antenna.campaign.records import CSV_COLUMNS, CampaignRow, RunResult
    from sensing_antenna.campaign.report import build_report
    from sensing_antenna.campaign.runner import run_campaign
    from sensing_antenna.campaign.runs import RunSpec, expand_runs
    from sensing_antenna.campaign.schema import (
        CalibrationStep,
        CampaignSpec,
        CampaignSpecError,
        DeviceSpec,
        FreeMotionStep,
        NoiseSweep,
    )
    from sensing_antenna.campaign.store import load_run_results, read_runs_csv
    from sensing_antenna.campaign.summary import CampaignSummary, summarize_campaign

__all__ = [
    "CSV_COLUMNS",
    "CalibrationStep",
    "CampaignRow",
    "CampaignSpec",
    "CampaignSpecError",
    "CampaignSummary",
    "DeviceSpec",
    "FreeMotionStep",
    "NoiseSweep",
    "RunResult",
    "RunSpec",
    "build_report",
    "default_campaign_spec",
    "expand_runs",
    "load_campaign_spec",
    "load_run_results",
    "parse_campaign_spec",
    "read_runs_csv",
    "run_campaign",
    "summarize_campaign",
]

_WHERE = {
    "CSV_COLUMNS": "records",
    "CalibrationStep": "schema",
    "CampaignRow": "records",
    "CampaignSpec": "schema",
    "CampaignSpecError": "schema",
    "CampaignSummary": "summary",
    "DeviceSpec": "schema",
    "FreeMotionStep": "schema",
    "NoiseSweep": "schema",
    "RunResult": "records",
    "RunSpec": "runs",
    "build_report": "report",
    "default_campaign_spec": "parsing",
    "expand_runs": "runs",
    "load_campaign_spec": "parsing",
    "load_run_results": "store",
    "parse_campaign_spec": "parsing",
    "read_runs_csv": "store",
    "run_campaign": "runner",
    "summarize_campaign": "summary",
}


def __getattr__(name: str) -> Any:
    module = _WHERE.get(name)
    if module is None:
        raise AttributeError(f"module 'sensing_antenna.campaign' has no attribute {name!r}")
    return getattr(importlib.import_module(f"sensing_antenna.campaign.{module}"), name)


def __dir__() -> list[str]:
    return sorted(__all__)
