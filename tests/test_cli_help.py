"""Every ``--help`` describes its command in plain text and shows what each option defaults to.

Read from the help text itself, as a person sees it: a paragraph between the usage and the
first section, no reStructuredText markup, and every option that takes a value either required
(in the usage line without brackets, or its help says when) or with its default
(``(default: ...)``, or a help text that says what happens without it).
"""

from __future__ import annotations

import re
from importlib import metadata

import pytest

from sensing_antenna.calibration.frequency import LOSSES
from sensing_antenna.cli import calibrate, main
from sensing_antenna.estimation.methods.fast import FastConfig

#: Every command and subcommand.
COMMANDS = [
    [],
    ["beam"],
    ["simulate"],
    ["import"],
    ["import", "rosbag"],
    ["identify"],
    ["estimate"],
    ["listen"],
    ["replay"],
    ["calibrate"],
    ["campaign"],
    ["campaign", "run"],
    ["campaign", "report"],
    ["map"],
    ["plot"],
    ["plot", "sensing-curves"],
    ["plot", "recording"],
    ["plot", "estimate"],
]


def _help(command: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    with pytest.raises(SystemExit) as exc:
        main([*command, "--help"])
    assert exc.value.code == 0
    return capsys.readouterr().out


def _sections(text: str) -> tuple[str, str, str]:
    """(usage, description, the rest) of a help text."""
    usage, description, rest = text.split("\n\n", 2)
    return usage, description, rest


def _options(rest: str) -> dict[str, str]:
    """``{--flag METAVAR: help}`` for every option of the ``options:`` section."""
    block = rest.split("options:\n", 1)[1]
    entries: dict[str, str] = {}
    current = ""
    for line in block.splitlines():
        match = re.match(r"^  (-\S.*?)(?:  +(.*))?$", line)
        if match:
            current = match.group(1)
            entries[current] = match.group(2) or ""
        elif line.startswith("    ") and current:
            entries[current] += " " + line.strip()
    return entries


@pytest.mark.parametrize("command", COMMANDS, ids=lambda c: " ".join(c) or "antenna")
def test_help_has_a_plain_description(
    command: list[str], capsys: pytest.CaptureFixture[str]
) -> None:
    text = _help(command, capsys)
    usage, description, _ = _sections(text)
    assert usage.startswith("usage: antenna")
    assert len(description.split()) >= 12, description  # a paragraph, not a heading
    assert not re.search(r"``|`|:\w+:`|\*\*", text)  # no reStructuredText or Markdown markup


@pytest.mark.parametrize("command", COMMANDS, ids=lambda c: " ".join(c) or "antenna")
def test_every_option_with_a_value_shows_its_default_or_is_required(
    command: list[str], capsys: pytest.CaptureFixture[str]
) -> None:
    usage, _, rest = _sections(_help(command, capsys))
    usage = " ".join(usage.split())
    for option, text in _options(rest).items():
        flag, _, metavar = option.split(", ")[-1].partition(" ")
        if not metavar:
            continue  # a switch
        required = re.search(rf"(^|[ (|]){re.escape(flag)} ", usage) and f"[{flag}" not in usage
        assert required or "default" in text or "required" in text, f"{flag}: {text}"


def test_help_shows_the_defaults_the_commands_use(capsys: pytest.CaptureFixture[str]) -> None:
    options = _options(_sections(_help(["simulate"], capsys))[2])
    assert "(default: 3.0)" in options["--duration DURATION"]
    assert "(default: 1.0)" in options["--noise NOISE"]
    assert "(default: paper-2021)" in options["--antenna ANTENNA"]
    options = _options(_sections(_help(["estimate"], capsys))[2])
    assert f"the fast method's, {FastConfig().tolerance:g}" in options["--tolerance M"]
    assert calibrate.LOSS_NAMES == LOSSES


def test_a_group_without_its_subcommand_lists_them(capsys: pytest.CaptureFixture[str]) -> None:
    for group, names in (
        ("campaign", ("run", "report")),
        ("plot", ("sensing-curves", "recording")),
        ("import", ("rosbag",)),
    ):
        with pytest.raises(SystemExit) as exc:
            main([group])
        assert exc.value.code == 2
        err = capsys.readouterr().err.strip()
        assert err.count("\n") == 0 and err.startswith(f"antenna {group}: error: ")
        assert all(name in err for name in names)


def test_version_is_the_installed_package_s(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0
    assert capsys.readouterr().out == f"antenna {metadata.version('sensing-antenna')}\n"
