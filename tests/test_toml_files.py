"""Tests of sensing_antenna.toml_files, through the readers that use it (antennae here)."""

from __future__ import annotations

from pathlib import Path

import pytest

from sensing_antenna.antenna import AntennaConfigError, load_antenna
from sensing_antenna.toml_files import MAX_KEY_PARTS, MAX_TOML_BYTES


def test_deep_or_huge_toml_is_refused_naming_the_file(tmp_path: Path) -> None:
    path = tmp_path / "deep.toml"
    path.write_text("x = " + "{a = " * 100_000 + "1" + "}" * 100_000 + "\n", encoding="utf-8")
    with pytest.raises(AntennaConfigError, match=r"deep.toml: file: .*nested too deeply"):
        load_antenna(path)
    path.write_text("x = " + "[" * 100_000 + "1" + "]" * 100_000 + "\n", encoding="utf-8")
    with pytest.raises(AntennaConfigError, match=r"deep.toml: file: .*nested too deeply"):
        load_antenna(path)
    # Python's TOML parser keeps every prefix of a dotted key: memory grows with the square of
    # its length. A key of 1000 parts (4 MB to parse) stands for the 100,000 (40 GB).
    path.write_text("[link]\nx" + ".a" * 999 + " = 1\n", encoding="utf-8")
    with pytest.raises(AntennaConfigError, match=r"deep.toml: file: line 2: a key of 1000 dotted"):
        load_antenna(path)
    path.write_text("[" + ".".join(["a"] * 40) + "]\n", encoding="utf-8")
    with pytest.raises(AntennaConfigError, match=f"40 dotted parts, more than .* {MAX_KEY_PARTS}"):
        load_antenna(path)
    with path.open("wb") as stream:
        stream.truncate(MAX_TOML_BYTES + 1)
    with pytest.raises(AntennaConfigError, match=r"deep.toml: file: .* larger than the limit"):
        load_antenna(path)


@pytest.mark.parametrize("key", ['"a\\nb"', '"a\\u2028b"', '"tab\\there"', '"\\u0000"'])
def test_an_unknown_key_with_a_line_break_is_named_on_one_line(key: str, tmp_path: Path) -> None:
    # TOML allows any character in a quoted key; the error must stay one line that shows the
    # key with its escapes (the command line prints one line). Found by the fuzz suite.
    from sensing_antenna.campaign.parsing import load_campaign_spec
    from sensing_antenna.campaign.schema import CampaignSpecError

    antenna = tmp_path / "antenna.toml"
    antenna.write_text(f'base = "paper-2021"\n[link]\n{key} = 1\n', encoding="utf-8")
    with pytest.raises(AntennaConfigError) as caught:
        load_antenna(antenna)
    message = str(caught.value)
    assert message.isprintable() and str(antenna) in message and "unknown key" in message
    spec = tmp_path / "spec.toml"
    spec.write_text(f'base = "default"\n{key} = 1\n', encoding="utf-8")
    with pytest.raises(CampaignSpecError) as caught_spec:
        load_campaign_spec(spec)
    assert str(caught_spec.value).isprintable()
