"""``antenna campaign run|report``: run an experiment campaign and build its report."""

from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path
from typing import Any

from sensing_antenna.cli.arguments import ArgumentError, add_actions, integer
from sensing_antenna.cli.estimate import METHOD_NAMES

#: Exit code of ``campaign run`` when every run was tried but some are stored as failed.
EXIT_RUNS_FAILED = 1


def register(subparsers: Any) -> None:
    """Add ``antenna campaign`` with its ``run`` and ``report`` subcommands."""
    parser = subparsers.add_parser(
        "campaign",
        help="run experiment campaigns (Section 5.6) and build their reports",
        description=(
            "A campaign is a declarative experiment (a TOML spec, docs/campaigns.md): simulated "
            "manoeuvres at chosen contact points and noise levels, each estimated by the chosen "
            "methods. run executes every run of a spec into a directory, resuming an "
            "interrupted one; report rebuilds the tables, figures and report.md of a directory."
        ),
    )
    actions = add_actions(parser, "action", "ACTION")

    run = actions.add_parser(
        "run",
        help="simulate and estimate every run of a campaign (resumes an interrupted one)",
        description=(
            "Simulates and estimates every run of the campaign SPEC (without SPEC, the built-in "
            "paper-2021 campaign of Section 5.6) in parallel, storing each finished run in the "
            "--out directory, then writes the report. Run again on the same directory, it "
            "resumes: runs already stored are not run again."
        ),
    )
    run.add_argument(
        "spec", nargs="?", default=None, help="campaign TOML file (default: paper-2021's)"
    )
    run.add_argument("--out", type=Path, required=True, help="campaign directory")
    run.add_argument(
        "--workers",
        type=integer(low=1),
        default=None,
        metavar="N",
        help="local processes (default: the machine's cores)",
    )
    run.add_argument(
        "--scheduler",
        default=None,
        help="Dask scheduler address tcp://HOST:PORT (default: local processes)",
    )
    run.add_argument("--retry-failed", action="store_true", help="redo runs stored as failed")
    run.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")
    run.add_argument(
        "--methods",
        default=None,
        help="comma-separated methods instead of the spec's, e.g. paper,ratio,two-frequency,fast "
        "(default: the spec's)",
    )
    run.set_defaults(func=_run)

    report = actions.add_parser(
        "report",
        help="rebuild tables, figures and report.md",
        description=(
            "Reads the runs stored in a campaign directory and writes its tables, figures and "
            "report.md again, without running anything."
        ),
    )
    report.add_argument("directory", type=Path, help="campaign directory")
    report.set_defaults(func=_report)


def _run(args: argparse.Namespace) -> int:
    from sensing_antenna.campaign.parsing import load_campaign_spec
    from sensing_antenna.campaign.report import build_report
    from sensing_antenna.campaign.runner import run_campaign

    spec = load_campaign_spec(args.spec)
    if args.methods is not None:
        methods = tuple(m.strip() for m in args.methods.split(",") if m.strip())
        unknown = [m for m in methods if m not in METHOD_NAMES]
        if unknown or not methods:
            # the flag's error, not the spec file's
            raise ArgumentError(
                "--methods",
                (f"unknown {unknown[0]!r}" if unknown else "no method given")
                + f" (comma-separated, from {', '.join(METHOD_NAMES)})",
            )
        spec = dataclasses.replace(spec, methods=methods)
    # a signal stops the campaign as CampaignInterrupted, whose message says what is kept; the
    # command line ends on it as on any interruption
    outcome = run_campaign(
        spec,
        args.out,
        workers=args.workers,
        scheduler=args.scheduler,
        retry_failed=args.retry_failed,
        progress=not args.no_progress,
    )
    print(
        f"{outcome.n_runs} runs: {outcome.n_previously_done} already done, "
        f"{outcome.n_executed} run now, {outcome.n_failed} failed"
    )
    foreign = outcome.foreign_run_files
    if foreign:
        more = f" and {len(foreign) - 10} more" if len(foreign) > 10 else ""
        print(
            f"antenna campaign run: left out {len(foreign)} run file(s) in "
            f"{outcome.out_dir / 'runs'} that are not runs of this spec: "
            f"{', '.join(foreign[:10])}{more}",
            file=sys.stderr,
        )
    print(build_report(outcome.out_dir))
    if outcome.n_failed:
        print(
            f"antenna campaign run: {outcome.n_failed} run(s) failed (listed in the report); "
            "--retry-failed runs them again",
            file=sys.stderr,
        )
        return EXIT_RUNS_FAILED
    return 0


def _report(args: argparse.Namespace) -> int:
    from sensing_antenna.campaign.report import build_report

    print(build_report(args.directory))
    return 0
