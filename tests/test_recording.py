"""Tests of the recording format (spec: docs/recording-format.md)."""

from __future__ import annotations

import gzip
import re
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sensing_antenna.antenna import paper_antenna
from sensing_antenna.recording import (
    FORMAT_NAME,
    MAX_FILE_BYTES,
    MAX_PERIODS_PER_SAMPLE,
    MAX_SAMPLES,
    MIN_SAMPLE_PERIOD,
    Recording,
    RecordingError,
    check_sampling,
    is_ground_truth_key,
    read_recording,
    resample_uniform,
    write_recording,
)
from sensing_antenna.torque_point import TORQUE_POINT_KEY

DATA = Path(__file__).parent / "data"


def _recording(n: int = 5, period: float = 1e-3, **kwargs: object) -> Recording:
    rng = np.random.default_rng(7)
    t = period * np.arange(n)
    return Recording(
        t=t,
        theta=rng.normal(size=(n, 2)),
        force=rng.normal(size=(n, 3)),
        torque=rng.normal(size=(n, 3)),
        **kwargs,  # type: ignore[arg-type]
    )


def test_spec_sign_check_example_matches_gravity_terms() -> None:
    # Spec "Sign check": theta2 = 0, at rest, nothing touching: F ~ (0, 0, -m_b g) and torque ~
    # (0, +0.5 m_b g l, 0), i.e. F_g^m and Gamma_g^m of Section 4.2. The file holds them rounded
    # to 3 significant digits, hence the 1e-4 absolute tolerance (N, N m).
    rec = read_recording(DATA / "rec_sign_check.csv")
    antenna = paper_antenna()
    np.testing.assert_allclose(rec.force[0], antenna.gravity_force(0.0), atol=1e-4)
    np.testing.assert_allclose(rec.torque[0], antenna.gravity_torque(0.0), atol=1e-4)
    assert rec.metadata["format"] == FORMAT_NAME
    assert list(rec.metadata) == ["format", "sample_period", "antenna", "description"]
    assert rec.sample_period == 0.001
    assert rec.source == str(DATA / "rec_sign_check.csv")
    assert not rec.sampling.irregular


def test_no_metadata_columns_in_other_order_and_extra_column() -> None:
    rec = read_recording(DATA / "rec_no_metadata_reordered.csv")
    assert dict(rec.metadata) == {}
    np.testing.assert_array_equal(rec.t, [0.0, 0.001, 0.002])
    np.testing.assert_array_equal(rec.theta[1], [0.02, 0.03])
    np.testing.assert_array_equal(rec.force[2], [-0.12, -0.22, -0.32])
    np.testing.assert_array_equal(rec.torque[0], [0.1, 0.2, 0.3])
    assert list(rec.extra) == ["theta1_ref"]
    np.testing.assert_array_equal(rec.extra["theta1_ref"], [0.015, 0.025, 0.035])
    assert rec.sample_period == pytest.approx(0.001, rel=1e-12)


def test_blank_lines_among_the_samples_are_left_out_and_every_line_keeps_its_number(
    tmp_path: Path,
) -> None:
    # an empty line and one of spaces among the samples: no sample, left out; a text column
    # the format does not name is still left out whole, and a bad cell or a time going back
    # after them is named at its own line (lines 1 and 2: metadata and header)
    header = "# sample_period: 0.001\nt,theta1,theta2,fx,fy,fz,tx,ty,tz,state\n"
    rows = [f"{k / 1000},0,0,0,0,-0.045,0,0.022,0,idle" for k in range(4)]
    path = tmp_path / "blank.csv"
    path.write_text(header + "\n".join([rows[0], "", rows[1], "   ", rows[2], rows[3]]) + "\n")
    rec = read_recording(path)
    np.testing.assert_array_equal(rec.t, [0.0, 0.001, 0.002, 0.003])
    assert "state" not in rec.extra
    bad = rows[2].replace(",0,0,0,", ",x,0,0,", 1)  # theta1 on line 7
    path.write_text(header + "\n".join([rows[0], "", rows[1], "   ", bad, rows[3]]) + "\n")
    with pytest.raises(RecordingError, match=r"blank\.csv:7: column 'theta1': not a number"):
        read_recording(path)
    back = rows[3].replace("0.003,", "0.0005,", 1)  # line 8
    path.write_text(header + "\n".join([rows[0], "", rows[1], "   ", rows[2], back]) + "\n")
    with pytest.raises(RecordingError, match=r"blank\.csv:8: column 't': time does not"):
        read_recording(path)


def test_crlf_line_endings() -> None:
    rec = read_recording(DATA / "rec_crlf.csv")
    assert rec.metadata["antenna"] == "paper-2021"
    assert rec.n_samples == 2
    np.testing.assert_array_equal(rec.theta[1], [0.1, 0.2])


@pytest.mark.parametrize(
    ("name", "line", "field", "words"),
    [
        ("bad_not_a_number.csv", 4, "fx", "not a number ('abc')"),
        ("bad_empty_cell.csv", 3, "fy", "not a number"),
        ("bad_missing_column.csv", 1, "tz", "missing"),
        ("bad_nan.csv", 3, "ty", "not a finite number"),
        ("bad_inf.csv", 3, "theta2", "not a finite number"),
        ("bad_time_not_increasing.csv", 4, "t", "does not increase"),
        ("bad_truncated.csv", 5, None, "truncated"),
        ("bad_empty.csv", None, None, "empty file"),
        ("bad_header_only.csv", 2, None, "no data rows"),
        ("bad_metadata_line.csv", 2, None, "# key: value"),
        ("bad_sample_period.csv", 1, "sample_period", "number > 0"),
        ("bad_format_version.csv", 1, "format", "unsupported version"),
        ("bad_duplicate_column.csv", 1, "fx", "duplicate column"),
        ("no_such_file.csv", None, None, "cannot read"),
    ],
)
def test_bad_input_names_file_line_and_field(
    name: str, line: int | None, field: str | None, words: str
) -> None:
    path = DATA / name
    with pytest.raises(RecordingError) as info:
        read_recording(path)
    err = info.value
    assert err.path == str(path)
    assert err.line == line
    assert err.field == field
    assert words in err.problem
    message = str(err)
    assert message.startswith(str(path) + (f":{line}:" if line is not None else ":"))
    if field is not None:
        assert repr(field) in message


def test_error_message_format_of_the_brief() -> None:
    err = RecordingError("rec.csv", 17, "fx", "not a number ('abc')")
    assert str(err) == "rec.csv:17: column 'fx': not a number ('abc')"
    err = RecordingError("rec.csv", 2, "sample_period", "must be a number > 0", metadata=True)
    assert str(err) == "rec.csv:2: metadata key 'sample_period': must be a number > 0"


def test_non_utf8_file(tmp_path: Path) -> None:
    path = tmp_path / "latin1.csv"
    path.write_bytes(b"# description: caf\xe9\nt,theta1\n")
    with pytest.raises(RecordingError, match=r"latin1.csv:1: not UTF-8"):
        read_recording(path)


def test_write_puts_format_and_period_first_and_is_deterministic(tmp_path: Path) -> None:
    rec = _recording(metadata={"antenna": "paper-2021", "true_xc": "0.5"})
    first, second = tmp_path / "a.csv", tmp_path / "b.csv"
    write_recording(rec, first)
    write_recording(read_recording(first), second)
    lines = first.read_text("utf-8").splitlines()
    assert lines[0] == f"# format: {FORMAT_NAME}"
    assert lines[1] == "# sample_period: 0.001"
    assert lines[4] == "t,theta1,theta2,fx,fy,fz,tx,ty,tz"
    assert first.read_bytes() == second.read_bytes()


_finite = st.floats(allow_nan=False, allow_infinity=False, width=64)
_key = st.text(alphabet="abcdefghijklmnopqrstuvwxyz_0123456789", min_size=1, max_size=12)
_value = st.text(
    alphabet=st.characters(blacklist_categories=("Cs", "Cc", "Zl", "Zp")), max_size=20
).map(str.strip)


@st.composite
def _recordings(draw: st.DrawFn) -> Recording:
    n = draw(st.integers(min_value=2, max_value=12))
    # Irregular steps (jitter, drops) around any period: a quarter to four periods each, so the
    # span stays within MAX_PERIODS_PER_SAMPLE of the median step, and the median step is at
    # least MIN_SAMPLE_PERIOD, as the format requires.
    period = draw(st.floats(min_value=4 * MIN_SAMPLE_PERIOD, max_value=1.0))
    multiples = draw(
        st.lists(st.floats(min_value=0.25, max_value=4.0), min_size=n - 1, max_size=n - 1)
    )
    steps = [period * m for m in multiples]
    t = draw(st.floats(min_value=-10.0, max_value=10.0)) + np.concatenate([[0.0], np.cumsum(steps)])
    if not np.all(np.diff(t) > 0):
        t = np.arange(n, dtype=float)
    grid = st.lists(_finite, min_size=n, max_size=n)
    columns = [draw(grid) for _ in range(8)]
    # A stated torque point is read (the torques moved to O), not carried: tested on its own.
    reserved = ("format", "sample_period", TORQUE_POINT_KEY)
    keys = draw(st.lists(_key.filter(lambda k: k not in reserved), unique=True))
    metadata = {"format": FORMAT_NAME, "sample_period": repr(float(np.median(np.diff(t))))}
    metadata.update({k: draw(_value) for k in keys})
    extra_names = draw(
        st.lists(st.sampled_from(["theta1_ref", "theta2_ref", "true_x"]), unique=True)
    )
    return Recording(
        t=t,
        theta=np.column_stack(columns[0:2]),
        force=np.column_stack(columns[2:5]),
        torque=np.column_stack(columns[5:8]),
        metadata=metadata,
        extra={name: np.asarray(draw(grid)) for name in extra_names},
    )


@settings(max_examples=60, deadline=None)
@given(rec=_recordings())
def test_round_trip_is_exact(rec: Recording, tmp_path_factory: pytest.TempPathFactory) -> None:
    path = tmp_path_factory.mktemp("rt") / "rec.csv"
    write_recording(rec, path)
    back = read_recording(path)
    assert back == rec
    assert back.source == str(path)


def test_writer_adds_period_when_metadata_lacks_it(tmp_path: Path) -> None:
    rec = _recording(metadata={"antenna": "x"})
    write_recording(rec, tmp_path / "r.csv")
    back = read_recording(tmp_path / "r.csv")
    assert list(back.metadata) == ["format", "sample_period", "antenna"]
    assert float(back.metadata["sample_period"]) == rec.sample_period
    np.testing.assert_array_equal(back.torque, rec.torque)


def test_ground_truth_keys_and_without_ground_truth() -> None:
    assert is_ground_truth_key("true_xc")
    assert is_ground_truth_key("seed")
    assert is_ground_truth_key("simulation")
    assert not is_ground_truth_key("sample_period")
    assert not is_ground_truth_key("antenna")
    rec = _recording(
        metadata={"antenna": "a", "true_xc": "0.4", "seed": "3", "simulation": "{}"},
        extra={"theta1_ref": np.zeros(5), "true_contact": np.ones(5)},
    )
    clean = rec.without_ground_truth()
    assert dict(clean.metadata) == {"antenna": "a"}
    assert list(clean.extra) == ["theta1_ref"]
    np.testing.assert_array_equal(clean.theta, rec.theta)


def test_with_metadata_keeps_order_and_appends() -> None:
    rec = _recording(metadata={"a": "1", "b": "2"}).with_metadata(a=3, c="x")
    assert list(rec.metadata.items()) == [("a", "3"), ("b", "2"), ("c", "x")]


def test_recording_is_immutable() -> None:
    rec = _recording()
    with pytest.raises(ValueError, match="read-only"):
        rec.theta[0, 0] = 1.0
    with pytest.raises(TypeError):
        rec.metadata["x"] = "y"  # type: ignore[index]


def test_recording_validation() -> None:
    with pytest.raises(RecordingError, match="strictly increasing"):
        Recording(
            t=[0.0, 0.0], theta=np.zeros((2, 2)), force=np.zeros((2, 3)), torque=np.zeros((2, 3))
        )
    with pytest.raises(RecordingError, match="shape"):
        Recording(
            t=[0.0, 1.0], theta=np.zeros((2, 3)), force=np.zeros((2, 3)), torque=np.zeros((2, 3))
        )
    with pytest.raises(RecordingError, match="NaN"):
        Recording(
            t=[0.0, 1.0],
            theta=np.zeros((2, 2)),
            force=np.full((2, 3), np.nan),
            torque=np.zeros((2, 3)),
        )
    with pytest.raises(RecordingError, match="edge spaces"):
        _recording(metadata={"a": " padded"})


def test_check_sampling_regular_jitter_and_drops() -> None:
    t = 1e-3 * np.arange(100)
    regular = check_sampling(t)
    assert not regular.irregular
    assert regular.n_dropped == 0
    assert regular.median_period == pytest.approx(1e-3, rel=1e-12)
    rng = np.random.default_rng(1)
    jittered = t + rng.uniform(-5e-5, 5e-5, size=t.size)  # +-5 % of the period
    diag = check_sampling(jittered, nominal=1e-3)
    assert diag.irregular
    assert diag.n_dropped == 0
    assert 1e-5 < diag.max_jitter <= 1e-4 + 1e-12  # two +-5e-5 shifts at most
    dropped = np.delete(t, [10, 50, 51])
    diag = check_sampling(dropped)
    assert diag.irregular
    assert diag.n_dropped == 3
    assert diag.max_jitter < 1e-15


def test_stamps_whose_clock_runs_off_the_period_make_sampling_irregular() -> None:
    # 2,000 stamps one period apart: 0.2 % off the nominal period spans 4 periods more than
    # the nominal, beyond 0.1 % and half a period; 0.05 % is within
    t = 1e-3 * np.arange(2000)
    off = check_sampling(t, nominal=1e-3 / 1.002)
    assert off.irregular and off.n_dropped == 0
    assert off.mean_period == pytest.approx(1e-3, rel=1e-12)
    assert off.max_jitter < 0.01 * off.nominal_period  # not the jitter: the clock
    assert not check_sampling(t, nominal=1e-3 / 1.0005).irregular
    # a short record may not tell: half a period over 100 steps is 0.5 %
    assert not check_sampling(t[:100], nominal=1e-3 / 1.004).irregular


def test_sample_period_falls_back_to_median_when_metadata_inconsistent() -> None:
    rec = _recording(metadata={"sample_period": "0.002"})
    assert rec.sample_period == pytest.approx(1e-3, rel=1e-12)
    assert _recording(metadata={"sample_period": "0.00101"}).sample_period == 0.00101


def test_a_sample_period_the_time_stamps_contradict_is_named() -> None:
    problem = _recording(metadata={"sample_period": "0.002"}).period_problem
    assert problem is not None and "'sample_period'" in problem and "0.5 times" in problem
    assert _recording(metadata={"sample_period": "0.00101"}).period_problem is None
    assert _recording(metadata={}).period_problem is None


def test_resample_uniform_is_exact_on_linear_signals() -> None:
    # Linear interpolation reproduces a linear signal exactly (to rounding): a clear reference.
    t = 1e-3 * np.delete(np.arange(50), [7, 20, 21]) + np.linspace(0, 2e-5, 47)
    theta = np.column_stack([2.0 * t, -3.0 * t + 1.0])
    force = np.column_stack([t, t, t])
    rec = Recording(
        t=t,
        theta=theta,
        force=force,
        torque=force,
        metadata={"sample_period": "0.001"},
        extra={"theta1_ref": 5.0 * t},
    )
    assert rec.sampling.irregular
    uniform = resample_uniform(rec)
    assert not uniform.sampling.irregular
    assert uniform.t[0] == t[0]
    assert uniform.t[-1] <= t[-1]
    np.testing.assert_allclose(np.diff(uniform.t), 1e-3, rtol=1e-9)
    np.testing.assert_allclose(uniform.theta[:, 0], 2.0 * uniform.t, atol=1e-12)
    np.testing.assert_allclose(uniform.theta[:, 1], -3.0 * uniform.t + 1.0, atol=1e-12)
    np.testing.assert_allclose(uniform.extra["theta1_ref"], 5.0 * uniform.t, atol=1e-12)
    assert uniform.metadata["sample_period"] == "0.001"


def test_reads_5000_rows(tmp_path: Path) -> None:
    # Functional check of the fast path on a 5 s, 1 kHz file; speed is measured in benchmarks.
    rec = _recording(n=5000)
    write_recording(rec, tmp_path / "big.csv")
    back = read_recording(tmp_path / "big.csv")
    assert back.n_samples == 5000
    for name in ("t", "theta", "force", "torque"):
        np.testing.assert_array_equal(getattr(back, name), getattr(rec, name))


def _write_rows(path: Path, t: np.ndarray, period: float = 1e-3) -> None:
    rows = "".join(f"{v!r},0,0,0,0,-0.0451,0,0.0221,0\n" for v in t.tolist())
    path.write_text(
        f"# sample_period: {period!r}\nt,theta1,theta2,fx,fy,fz,tx,ty,tz\n{rows}", encoding="utf-8"
    )


def test_an_outlier_time_stamp_is_refused_at_its_line(tmp_path: Path) -> None:
    # One last stamp at 1e6 s in a 1 kHz file: its resampled grid would hold 1e9 samples per
    # column. The reader refuses it up front, naming the line (header on line 2, so sample k
    # is on line k + 3), the column t and the step.
    t = 1e-3 * np.arange(3000)
    t[-1] = 1e6
    path = tmp_path / "outlier.csv"
    _write_rows(path, t)
    with pytest.raises(RecordingError) as info:
        read_recording(path)
    err = info.value
    assert (err.line, err.field) == (3002, "t")
    assert "outlier time stamp or a gap" in err.problem
    assert "from 2.998 to 1000000.0 s" in err.problem
    assert f"limit of {MAX_SAMPLES} samples" in err.problem


def test_a_mostly_empty_span_is_refused_at_its_gap(tmp_path: Path) -> None:
    # 1000 samples at 1 ms, then a jump of 1000 s and 1000 more: the span holds 1e6 periods for
    # 2000 samples, 500 per sample, more than MAX_PERIODS_PER_SAMPLE; the gap ends on line 1003.
    t = np.concatenate([1e-3 * np.arange(1000), 1000.0 + 1e-3 * np.arange(1000)])
    path = tmp_path / "gap.csv"
    _write_rows(path, t)
    with pytest.raises(RecordingError) as info:
        read_recording(path)
    assert (info.value.line, info.value.field) == (1003, "t")
    assert f"{MAX_PERIODS_PER_SAMPLE} per sample for its 2000 samples" in info.value.problem
    # A first stamp far before the others is named on its own line (line 3).
    t = 1e-3 * np.arange(2000)
    t[0] = -1e4
    _write_rows(path, t)
    with pytest.raises(RecordingError) as info:
        read_recording(path)
    assert info.value.line == 3
    # The bound itself: 20 samples, 19 of them 1 ms apart, may span up to 100 * 20 = 2000
    # periods: a last stamp at 1.9 s (1900 periods) is a gap the estimators handle, 2.1 s is not.
    t = 1e-3 * np.arange(20)
    t[-1] = 1.9
    _write_rows(path, t)
    assert read_recording(path).sampling.n_dropped == 1900 - 19
    t[-1] = 2.1
    _write_rows(path, t)
    with pytest.raises(RecordingError, match="2100 periods"):
        read_recording(path)


def test_a_sample_period_no_sensor_has_is_refused_as_a_unit_error(tmp_path: Path) -> None:
    # Time stamps in ns read as s (a 1 kHz file: steps of 1e-12 s) or 1e-17 s apart: the
    # detectors' filters would have poles of 1 in floating point. Refused at the second sample,
    # in a file and in memory; 1 us (a 1 MHz logger) is still read.
    path = tmp_path / "ns.csv"
    for step in (1e-12, 1e-17):
        _write_rows(path, step * np.arange(100), period=step)
        with pytest.raises(RecordingError) as info:
            read_recording(path)
        assert (info.value.line, info.value.field) == (4, "t")
        assert "another unit than seconds" in info.value.problem
        with pytest.raises(RecordingError, match="shorter than 1e-06 s"):
            Recording(
                t=step * np.arange(100),
                theta=np.zeros((100, 2)),
                force=np.zeros((100, 3)),
                torque=np.zeros((100, 3)),
            )
    _write_rows(path, MIN_SAMPLE_PERIOD * np.arange(100), period=MIN_SAMPLE_PERIOD)
    assert read_recording(path).sample_period == MIN_SAMPLE_PERIOD


def test_recordings_in_memory_and_the_resampler_refuse_the_same_spans() -> None:
    t = 1e-3 * np.arange(3000)
    t[-1] = 1e6
    with pytest.raises(RecordingError, match=r"column 't': sample 2999: time jumps"):
        Recording(
            t=t, theta=np.zeros((3000, 2)), force=np.zeros((3000, 3)), torque=np.zeros((3000, 3))
        )
    rec = _recording(n=1000)
    with pytest.raises(RecordingError, match=f"more than the limit of {MAX_SAMPLES}"):
        resample_uniform(rec, period=1e-12)


def test_binary_content_is_not_a_recording(tmp_path: Path) -> None:
    path = tmp_path / "nul.csv"
    path.write_bytes(b"# antenna: x\nt,theta1\n0.0\x00,1\n")
    with pytest.raises(RecordingError, match=r"nul.csv:3: not a recording: binary content"):
        read_recording(path)


@pytest.mark.skipif(not Path("/dev/zero").exists(), reason="needs /dev/zero")
def test_an_endless_device_is_refused_at_once() -> None:
    # /dev/zero never ends: read whole, it exhausts memory; its first byte is a NUL.
    with pytest.raises(RecordingError, match=r"/dev/zero:1: not a recording"):
        read_recording("/dev/zero")


def test_a_file_above_the_size_limit_is_refused_before_reading(tmp_path: Path) -> None:
    path = tmp_path / "large.csv"
    with path.open("wb") as stream:  # sparse: no disk space used
        stream.truncate(MAX_FILE_BYTES + 1)
    with pytest.raises(RecordingError, match=f"larger than the reader's limit of {MAX_FILE_BYTES}"):
        read_recording(path)


@pytest.mark.parametrize(("cell", "shown"), [("nan", "nan"), ("-inf", "-inf"), ("1e400", "inf")])
def test_messages_show_plain_numbers(tmp_path: Path, cell: str, shown: str) -> None:
    path = tmp_path / "r.csv"
    path.write_text(f"t,theta1,theta2,fx,fy,fz,tx,ty,tz\n0,0,0,{cell},0,0,0,0,0\n", "utf-8")
    with pytest.raises(RecordingError) as info:
        read_recording(path)
    assert str(info.value) == f"{path}:2: column 'fx': {shown} is not a finite number"
    path.write_text(
        "t,theta1,theta2,fx,fy,fz,tx,ty,tz\n0.5,0,0,0,0,0,0,0,0\n0.25,0,0,0,0,0,0,0,0\n"
    )
    with pytest.raises(RecordingError) as info:
        read_recording(path)
    assert info.value.problem == "time does not increase (0.25 after 0.5)"


@pytest.mark.parametrize("value", ["a\u2028b", "a\x0cb", "a\x85b", "a\x00b"])
def test_metadata_that_would_not_read_back_is_refused(value: str, tmp_path: Path) -> None:
    # str.splitlines (the reader) breaks lines at these characters, and a NUL is binary content:
    # written, they would not read back as one metadata value.
    with pytest.raises(RecordingError, match="one line"):
        _recording(metadata={"description": value})


@pytest.mark.parametrize(("separator", "called"), [(";", "semicolons"), ("\t", "tabs")])
def test_a_header_with_another_separator_says_which(
    separator: str, called: str, tmp_path: Path
) -> None:
    path = tmp_path / "semicolons.csv"
    write_recording(_recording(), path)
    lines = path.read_text().splitlines()
    path.write_text(
        "\n".join(line if line.startswith("#") else line.replace(",", separator) for line in lines)
        + "\n"
    )
    with pytest.raises(RecordingError, match=f"one column separated by {called}"):
        read_recording(path)


def test_a_compressed_recording_is_named_as_such(tmp_path: Path) -> None:
    # a lab's archive of logs, given as is: not "binary content" but what it is
    path = tmp_path / "rec.csv"
    write_recording(_recording(), path)
    packed = tmp_path / "rec.csv.gz"
    packed.write_bytes(gzip.compress(path.read_bytes()))
    with pytest.raises(RecordingError, match=r"rec\.csv\.gz: a gzip-compressed file: not read"):
        read_recording(packed)


@pytest.mark.parametrize("written", ['"tz"', "TZ", "tz [N m]", "tz (Nm)"])
def test_a_required_name_written_otherwise_is_named_with_what_was_found(
    written: str, tmp_path: Path
) -> None:
    # a spreadsheet's quotes, a logger's capitals, a unit in the header: the column is there,
    # written otherwise, and the error shows how
    path = tmp_path / "header.csv"
    write_recording(_recording(), path)
    text = path.read_text().replace(",tz\n", f",{written}\n", 1)
    path.write_text(text)
    with pytest.raises(
        RecordingError,
        match=r"column 'tz': required column missing from header \(found "
        + re.escape(repr(written))
        + ": names are written bare and in lower case",
    ):
        read_recording(path)


def test_a_log_in_another_format_is_told_every_missing_column_and_where_to_convert_it(
    tmp_path: Path,
) -> None:
    path = tmp_path / "lab.csv"
    path.write_text(
        "time_us,az_deg,el_deg,Fx,Fy,Fz,Mx,My,Mz\n0,0,0,0,0,0,0,0,0\n1000,0,0,0,0,0,0,0,0\n"
    )
    with pytest.raises(RecordingError) as error:
        read_recording(path)
    said = str(error.value)
    assert "column 't': required column missing from header (found 'time_us': the time" in said
    assert "; missing too: theta1, theta2, fx, fy, fz, tx, ty, tz (a log in another" in said
    assert "docs/import.md" in said


@pytest.mark.parametrize(("name", "written"), [("theta2", "theta_2"), ("fy", "fy1")])
def test_a_required_name_misspelled_is_named_with_the_near_one(
    name: str, written: str, tmp_path: Path
) -> None:
    # a logger's own spelling of a column: the nearest unknown name is shown; a name the format
    # knows is never offered for another (theta1 is not theta2's misspelling)
    path = tmp_path / "header.csv"
    write_recording(_recording(), path)
    text = path.read_text().replace(f",{name},", f",{written},", 1)
    path.write_text(text)
    with pytest.raises(
        RecordingError,
        match=rf"column '{name}': required column missing from header \(found '{written}': "
        rf"is it '{name}'\?",
    ):
        read_recording(path)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        # numpy.savetxt(header=...) without comments=""
        (lambda text: text.replace("t,theta1", "# t,theta1", 1), "numpy.savetxt writes '# '"),
        # a blank line between the metadata and the header
        (lambda text: text.replace("\nt,theta1", "\n\nt,theta1", 1), "blank line where the header"),
        # pandas' to_csv with its index
        (lambda text: text.replace("\nt,theta1", "\n,t,theta1", 1), "an index, as pandas writes"),
        # a trailing comma after the last name
        (lambda text: text.replace(",tz\n", ",tz,\n", 1), "a trailing comma?"),
        # the time column spelled out
        (lambda text: text.replace("\nt,theta1", "\ntime,theta1", 1), "found 'time': the time"),
    ],
    ids=["savetxt", "blank", "index", "trailing-comma", "time"],
)
def test_a_header_as_common_tools_write_it_is_named_with_the_fix(
    change: object, message: str, tmp_path: Path
) -> None:
    path = tmp_path / "header.csv"
    write_recording(_recording(), path)
    path.write_text(change(path.read_text()))  # type: ignore[operator]
    with pytest.raises(RecordingError, match=re.escape(message)):
        read_recording(path)


def test_a_loggers_text_columns_and_footer_are_left_out(tmp_path: Path) -> None:
    # A lab's logger writes a state column, a sensor temperature it did not always read and a
    # footer; the samples read as without them. A '#' line among the samples is refused
    rows = [
        "t,phase,theta1,theta2,fx,fy,fz,tx,ty,tz,temp_C",
        "0.0,REST,0.0,0.0,0,0,-0.04,0,0.02,0,25.1",
        "0.001,SWEEP,0.001,0.0,0,0,-0.04,0,0.02,0,",
        "0.002,SWEEP,0.002,0.0,0,0,-0.04,0,0.02,0,nan",
    ]
    path = tmp_path / "lab.csv"
    path.write_text("\n".join([*rows, "# end: 3 samples", ""]))
    rec = read_recording(path)
    assert dict(rec.extra) == {}
    np.testing.assert_array_equal(rec.theta[:, 0], [0.0, 0.001, 0.002])
    np.testing.assert_array_equal(rec.torque[:, 1], [0.02] * 3)
    middle = tmp_path / "two.csv"
    middle.write_text("\n".join([*rows[:2], "# another recording", *rows[2:], ""]))
    with pytest.raises(RecordingError) as info:
        read_recording(middle)
    assert info.value.line == 3 and "a '#' line among the samples" in info.value.problem
    # a column the format names (the motor commands) is judged as the nine are
    commands = tmp_path / "commands.csv"
    commands.write_text(
        "t,theta1,theta2,fx,fy,fz,tx,ty,tz,u1,u2\n0,0,0,0,0,0,0,0,0,0.1,0.2\n0.001,0,0,0,0,0,0,0,0,,0.2\n"
    )
    with pytest.raises(RecordingError) as info:
        read_recording(commands)
    assert (info.value.line, info.value.field) == (3, "u1")
    text_required = tmp_path / "text.csv"
    text_required.write_text(
        "\n".join([*rows[:2], rows[2].replace("0.001,SWEEP,0.001", "0.001,SWEEP,x")])
    )
    with pytest.raises(RecordingError) as info:
        read_recording(text_required)
    assert (info.value.line, info.value.field) == (3, "theta1")
    # beside a text column, a cell is read as in a file without one: a digit group or another
    # script's digit (both numbers to Python) is no number there either
    for typo in ("1_0", "\u0661"):
        grouped = tmp_path / "grouped.csv"
        grouped.write_text("\n".join([*rows[:2], rows[2].replace(",0.001,0.0,", f",{typo},0.0,")]))
        with pytest.raises(RecordingError) as info:
            read_recording(grouped)
        assert (info.value.line, info.value.field) == (3, "theta1"), typo


def test_a_sample_period_with_a_digit_group_is_refused(tmp_path: Path) -> None:
    # '0_001' is 1.0 to Python's float: a typo that would stretch the recording a thousandfold
    path = tmp_path / "grouped.csv"
    path.write_text(
        "# sample_period: 0_001\nt,theta1,theta2,fx,fy,fz,tx,ty,tz\n0,0,0,0,0,0,0,0,0\n"
    )
    with pytest.raises(RecordingError) as info:
        read_recording(path)
    assert (info.value.line, info.value.field) == (1, "sample_period")


def _about(point: list[float], recording: Recording, path: Path) -> Path:
    """``recording`` written with its torques taken about ``point`` (S - O, m) and saying so."""
    moved = Recording(
        t=recording.t,
        theta=recording.theta,
        force=recording.force,
        torque=recording.torque - np.cross(point, recording.force),
        metadata=recording.metadata,
    )
    write_recording(moved, path)
    lines = path.read_text().splitlines(keepends=True)
    lines.insert(2, f"# torque_point: {point}\n")
    path.write_text("".join(lines))
    return path


def _with_metadata(path: Path, lines: str) -> Path:
    """A two-sample file at ``path`` with the metadata ``lines`` after format and period."""
    path.write_text(
        f"# format: {FORMAT_NAME}\n# sample_period: 0.001\n{lines}"
        "t,theta1,theta2,fx,fy,fz,tx,ty,tz\n0,0,0,0,0,0,0,0,0\n0.001,0,0,0,0,0,0,0,0\n"
    )
    return path


def test_torques_taken_about_the_sensors_origin_are_moved_to_o(tmp_path: Path) -> None:
    # Gamma_O = Gamma_S + (S - O) x F: a sensor 25 mm along the link and 4 mm above it
    original = _recording(50, metadata={"description": "head at rest"})
    path = _about([0.025, 0.0, 0.004], original, tmp_path / "s.csv")
    read = read_recording(path)
    np.testing.assert_allclose(read.torque, original.torque, rtol=0, atol=1e-15)
    np.testing.assert_array_equal(read.force, original.force)
    # the recording read is about O: written again, it reads the same, and says where from
    assert "torque_point" not in read.metadata
    assert read.metadata["torques_moved_from"] == "[0.025, 0.0, 0.004]"
    write_recording(read, tmp_path / "again.csv")
    assert read_recording(tmp_path / "again.csv") == read
    # a recording in memory holds torques about O only
    with pytest.raises(RecordingError, match=r"torque_point.*about O"):
        _recording(metadata={"torque_point": "[0.025, 0, 0]"})


@pytest.mark.parametrize(
    ("value", "problem"),
    [
        ("[25, 0, 4]", "25.32 m from O, more than 1 m: in metres?"),
        ("[0.02, 0]", "must be three numbers"),
        ('{"x": 0.02}', "must be three numbers"),
        ("[0.02, 0, NaN]", "must be finite"),
        ("[true, 0, 0]", "must be three numbers"),
        (f"[1{'0' * 400}, 0, 0]", "must be finite"),  # an integer no float holds
    ],
)
def test_a_torque_point_that_is_no_point_on_the_head_is_named(
    value: str, problem: str, tmp_path: Path
) -> None:
    path = _with_metadata(tmp_path / "bad.csv", f"# torque_point: {value}\n")
    with pytest.raises(RecordingError) as info:
        read_recording(path)
    assert str(info.value).startswith(f"{path}:3: metadata key 'torque_point': ")
    assert problem in info.value.problem


@pytest.mark.parametrize(
    ("lines", "key", "problem"),
    [
        ("# torque-point: [0.02, 0, 0]\n", "torque-point", "is spelled 'torque_point'"),
        ("# Torque_Point: [0.02, 0, 0]\n", "Torque_Point", "is spelled 'torque_point'"),
        (
            "# torque_point: [0.02, 0, 0]\n# torques_moved_from: [0.01, 0, 0]\n",
            "torques_moved_from",
            "one says the torques are about O already",
        ),
    ],
)
def test_a_torque_point_misspelled_or_contradicted_is_refused(
    lines: str, key: str, problem: str, tmp_path: Path
) -> None:
    # as written, the first two would leave the torques where they are, without a word
    path = _with_metadata(tmp_path / "bad.csv", lines)
    with pytest.raises(RecordingError) as info:
        read_recording(path)
    assert info.value.field == key and problem in info.value.problem


def test_a_sample_that_is_not_finite_is_named_by_column_and_row() -> None:
    # a recording built in Python (a lab's converter) with one NaN: the line says where it is
    t = 1e-3 * np.arange(5)
    torque = np.zeros((5, 3))
    torque[3, 1] = np.nan
    with pytest.raises(RecordingError) as info:
        Recording(t=t, theta=np.zeros((5, 2)), force=np.zeros((5, 3)), torque=torque)
    assert str(info.value) == (
        "<recording>: column 'torque': NaN or infinite value at row 3 (from 0): [0.0, nan, 0.0]"
    )
