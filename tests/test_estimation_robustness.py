"""Robustness of the pipeline to real contact dynamics and model error.

- the push is judged by the mean contact force over the hold after t_1, not at one instant
  (near the tip the link rebounds on the obstacle after the stop);
- a frequency candidate inconsistent with the ratio beyond the ratio's uncertainty is
  ``estimators_disagree``, e.g. when T of the sensing curve is 7 % off (Section 5.1);
- gaps of missing samples from t_c on, and corrupted runs too long to put back, are
  ``bad_input``;
- the human-readable output of a doubtful estimate says it is a best guess.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from _models import calibrated
from sensing_antenna.antenna import Antenna, load_antenna, paper_antenna
from sensing_antenna.cli.estimate import summary
from sensing_antenna.detection.push import PushCriterion
from sensing_antenna.estimation import (
    ContactEstimate,
    EstimatorConfig,
    OnlineEstimator,
    Status,
    estimate,
)
from sensing_antenna.estimation.front.held import repeated_rows
from sensing_antenna.estimation.front.spikes import spike_longest
from sensing_antenna.estimation.front.steps import declared_period_problem
from sensing_antenna.recording import Recording
from sensing_antenna.simulator import Scenario, simulate
from sensing_antenna.simulator.scenario import ATI_NANO17_RESOLUTION
from test_estimation_pipeline import Synthetic, comparable, synthetic_recording

#: The longest run put back at the synthetic recordings' 1 kHz.
SPIKE_LONGEST = spike_longest(1e-3)
GAP_LIMIT = EstimatorConfig().gap_limit(1e-3)


def test_push_judged_over_the_hold_despite_rebounds() -> None:
    # The case that showed it: seed 5, x_c = 0.9 m, observer identified on a free sweep. Near
    # the tip the link bounces on the post after the stop: the filtered force at t_1 was 1.9 mN
    # and the push "not reached", while the static preload is about 10 mN (simulator truth).
    from sensing_antenna.calibration.observer import identify_free_motion
    from sensing_antenna.simulator import Scenario, simulate

    antenna = calibrated()
    fit = identify_free_motion(
        simulate(antenna, Scenario(case="free", duration=3.0, seed=1)), antenna
    )
    antenna = dataclasses.replace(antenna, observer=fit.observer)
    recording = simulate(antenna, Scenario(case="azimuthal", contact_point=0.9, seed=5))
    result = estimate(recording, antenna)
    assert result.status is Status.OK, result.reason
    true_xc = float(recording.metadata["true_xc"])
    # The paper reports mean errors under 1 cm (Tables 3 and 4); here one run, far below it.
    assert result.x_c == pytest.approx(true_xc, abs=0.01)
    # The link does leave the post after the stop here (the simulator's contact flag is off for
    # 42 of the first 200 samples after it): the diagnostics must report rebounds, not hide them.
    assert result.diagnostics["rebounds"]["count"] >= 1


def test_gentle_push_is_measured_against_noise_not_a_fixed_force() -> None:
    # 0.2 % deflection at 0.9 m: |R| = 3 E I y_c / x_c^3 = 0.7 mN, far below the 5 mN of the
    # old absolute rule but 20 standard errors of the hold mean (3.1 mN noise / sqrt(201)).
    spec = Synthetic(x_c=0.9, deflection_ratio=0.002, seed=3)
    result = estimate(synthetic_recording(spec), calibrated())
    assert result.status is not Status.PUSH_NOT_REACHED, result.reason
    # With a tenth of that push, the mean is within the noise: no push.
    faint = Synthetic(x_c=0.9, deflection_ratio=0.00002, in_plane=400.0, out_of_plane=400.0)
    result = estimate(synthetic_recording(faint), calibrated())
    assert result.status in (Status.PUSH_NOT_REACHED, Status.NO_CONTACT), result.reason


def test_model_error_gives_disagreement_not_a_confident_answer() -> None:
    # Recording built with the theoretical T of the paper's link, estimated with the paper's
    # calibrated T_e, 7 % lower (Section 5.1): the inverse sensing curve of T_e puts the
    # measured omega_1 at 0.266 m for 0.3 m (3.4 cm off). The ratio does not depend on T; with a
    # 2 % deflection (60 mN push) its uncertainty is about 6 mm, so 3.4 cm is beyond 3 sigma.
    spec = Synthetic(x_c=0.3, deflection_ratio=0.02, seed=11)
    recording = synthetic_recording(spec)
    right = estimate(recording, calibrated())
    assert right.status is Status.OK, right.reason
    assert right.x_c == pytest.approx(0.3, abs=5e-3)
    wrong = estimate(recording, load_antenna("paper-2021-calibrated"))
    assert wrong.status is Status.ESTIMATORS_DISAGREE
    reason = wrong.reason or ""
    assert f"{wrong.x_c:.3f}" in reason and f"{wrong.ratio_estimate:.3f}" in reason
    # the distance is more than the stated number of the ratio's standard uncertainties
    sigma = wrong.diagnostics["ratio_uncertainty"]
    assert abs(wrong.x_c - wrong.ratio_estimate) > 3.0 * sigma
    assert math.isfinite(wrong.x_c)  # the best guess is still reported


def _drop(recording: Recording, start: int, count: int) -> Recording:
    keep = np.ones(recording.n_samples, dtype=bool)
    keep[start : start + count] = False
    return Recording(
        t=recording.t[keep],
        theta=recording.theta[keep],
        force=recording.force[keep],
        torque=recording.torque[keep],
        metadata={"sample_period": repr(recording.sample_period)},
    )


def test_gap_after_t1_is_bad_input_online_and_offline() -> None:
    recording = synthetic_recording(Synthetic(x_c=0.45, seed=2))
    whole = estimate(recording, calibrated())
    assert whole.ok
    i_1 = int(np.searchsorted(recording.t, whole.t_1))
    gapped = _drop(recording, i_1 + 300, 200)
    result = estimate(gapped, calibrated())
    assert result.status is Status.BAD_INPUT
    assert "200 samples missing" in (result.reason or "")
    online = OnlineEstimator(calibrated(), 1e-3)
    for k in range(gapped.n_samples):
        online.update(gapped.t[k], gapped.theta[k], gapped.force[k], gapped.torque[k])
    final = online.finalize()
    assert final.status is Status.BAD_INPUT and "200 samples missing" in (final.reason or "")
    # up to gap_limit (20 at 1 kHz) in a row are filled in on a line, the answer within 1 mm (a line
    # across 20 ms moves the spectrum's peak by far less: benchmarks/eval_glitches.py), and
    # antenna estimate says how many; 21 in a row are too many
    for count, expected in ((20, Status.OK), (21, Status.BAD_INPUT)):
        holed = _drop(recording, i_1 + 300, count)
        short = estimate(holed, calibrated())
        assert short.status is expected, (count, short.reason)
        online = OnlineEstimator(calibrated(), 1e-3)
        for k in range(holed.n_samples):
            online.update(holed.t[k], holed.theta[k], holed.force[k], holed.torque[k])
        final = online.finalize()  # the stream fills its gaps as they come: alike to rounding
        assert (final.status, final.reason) == (short.status, short.reason)
        assert final.x_c == pytest.approx(short.x_c, abs=1e-9)
        if expected is Status.OK:
            assert short.x_c == pytest.approx(whole.x_c, abs=1e-3)
            lines = summary("holed.csv", short.to_dict()).splitlines()
            assert "  missing         20 sample(s), bridged by straight lines" in lines
        else:
            assert "21 samples missing" in (short.reason or "")
            assert "at most 20 in a row are filled in" in (short.reason or "")


@pytest.mark.parametrize("where", ["t_c", "t_1"])
def test_a_gap_from_the_contact_on_is_bad_input_however_long(where: str) -> None:
    # From t_c the estimators read the push and the head's stop, which fixes t_1: a straight line
    # across a long gap there looks like the head at rest where it was still moving, and moves
    # t_1. Any gap longer than the limit from t_c on is bad_input, the longer ones too.
    recording = synthetic_recording(Synthetic(x_c=0.45, seed=2))
    whole = estimate(recording, calibrated())
    centre = int(np.searchsorted(recording.t, whole.t_c if where == "t_c" else whole.t_1))
    for count in (10, 21, 40, 60, 100):
        for method in ("paper", "fast"):
            result = estimate(_drop(recording, centre - count // 2, count), calibrated(), method)
            if count <= 20:
                assert result.status is Status.OK, (count, method, result.reason)
            else:
                assert result.status is Status.BAD_INPUT, (count, method, result.status)
                assert f"{count} samples missing" in (result.reason or "")


def test_a_gap_after_fast_answered_is_judged_only_by_the_methods_it_reaches() -> None:
    # fast answers about 0.35 s after t_1 (online, from the samples it has): a gap of 30
    # samples 0.8 s after t_1 comes after its answer, batch and stream alike, and lies inside
    # the paper method's 1 s spectrum window
    recording = synthetic_recording(Synthetic(x_c=0.45, seed=2))
    clean = estimate(recording, calibrated(), "fast")
    assert clean.ok and clean.t_e - clean.t_1 < 0.8
    i_1 = int(np.searchsorted(recording.t, clean.t_1))
    holed = _drop(recording, i_1 + 800, 30)
    fast = estimate(holed, calibrated(), "fast")
    assert fast.ok and fast.x_c == clean.x_c and fast.t_e == pytest.approx(clean.t_e)
    online = OnlineEstimator(calibrated(), 1e-3, method="fast")
    for k in range(holed.n_samples):
        online.update(holed.t[k], holed.theta[k], holed.force[k], holed.torque[k])
    assert online.finalize().status is Status.OK
    paper = estimate(holed, calibrated(), "paper")
    assert paper.status is Status.BAD_INPUT and "30 samples missing" in (paper.reason or "")
    # before its answer, the gap is fast's too
    early = estimate(_drop(recording, i_1 + 100, 30), calibrated(), "fast")
    assert early.status is Status.BAD_INPUT and "30 samples missing" in (early.reason or "")
    assert early.interval is None and early.diagnostics["interval_dropped"] is not None


def test_at_250_hz_gaps_are_bridged_for_20_ms_and_corrupted_runs_for_20_samples() -> None:
    # every fourth sample of a 1 kHz push. A gap is known from the time stamps, and one longer
    # than 20 ms (five samples) after t_1 is refused by name; a corrupted run is found only by
    # its shape, and one left in place misleads (docs/design-notes.md, "Samples lost inside
    # the window"), so twenty samples in a row are still put back, 80 ms here
    fine = synthetic_recording(Synthetic(x_c=0.5, seed=4))
    coarse = Recording(
        t=fine.t[::4],
        theta=fine.theta[::4],
        force=fine.force[::4],
        torque=fine.torque[::4],
        metadata={"sample_period": "0.004"},
    )
    clean = estimate(coarse, calibrated())
    assert clean.ok, clean.reason
    k = int(np.searchsorted(coarse.t, clean.t_1 + 0.05))
    for count in (5, 6):
        holed = estimate(_drop(coarse, k, count), calibrated())
        assert holed.status is (Status.OK if count == 5 else Status.BAD_INPUT), holed.reason
        assert holed.diagnostics["sampling"]["n_dropped"] == count
    for count in (6, 20, 21):
        torque = coarse.torque.copy()
        torque[k : k + count, 2] *= 50.0
        result = estimate(dataclasses.replace(coarse, torque=torque), calibrated())
        repaired = result.diagnostics.get("repaired_samples", [])
        assert [r["samples"] for r in repaired] == ([count] if count <= 20 else []), count
        if count <= 20:
            assert result.ok and abs(result.x_c - clean.x_c) < 1e-3, (count, result.reason)


@pytest.mark.parametrize("sample_period", [5e-4, 2e-3])
def test_a_device_sampled_at_2_khz_or_500_hz_is_read_as_at_1_khz(sample_period: float) -> None:
    # the simulated head's controller and samples at another rate: the same manoeuvre, so both
    # methods answer ok within the fast method's 3 mm target of the simulator's truth (at
    # 1 kHz both are within 0.3 mm here; at 500 Hz the window holds half the samples)
    antenna = calibrated()
    scenario = Scenario(case="azimuthal", contact_point=0.5, seed=2, sample_period=sample_period)
    recording = simulate(antenna, scenario)
    assert float(recording.metadata["sample_period"]) == sample_period
    assert recording.t[1] - recording.t[0] == pytest.approx(sample_period, rel=1e-9)
    truth = float(recording.metadata["true_xc"])
    for method in ("paper", "fast"):
        result = estimate(recording, antenna, method=method)
        assert result.ok, (method, result.reason)
        assert abs(result.x_c - truth) < 3e-3, method


def test_a_contact_found_inside_a_gap_is_said_to_be_maybe_the_gap() -> None:
    # 0.3 s lost while the head turns: the straight line across the gap is a jump the observer
    # of a low threshold cannot follow, and the detector fires on it
    antenna = calibrated()
    observer = dataclasses.replace(antenna.observer, contact_threshold=1e-4)
    model = dataclasses.replace(antenna, observer=observer)
    recording = simulate(antenna, Scenario(case="azimuthal", contact_point=0.55, seed=1))
    result = estimate(_drop(recording.without_ground_truth(), 300, 300), model)
    assert result.status is Status.BAD_INPUT
    assert "300 samples missing between 0.2990 s and 0.6000 s" in (result.reason or "")
    assert "the contact was found inside the gap" in (result.reason or "")


def test_gap_before_contact_is_interpolated() -> None:
    recording = synthetic_recording(Synthetic(x_c=0.45, seed=2))
    result = estimate(_drop(recording, 200, 50), calibrated())
    assert result.ok, result.reason


def test_online_equals_offline_near_the_tip_with_a_gentle_push() -> None:
    spec = Synthetic(x_c=0.95, deflection_ratio=0.01, seed=7, in_plane=2.0, out_of_plane=2.0)
    recording = synthetic_recording(spec)
    offline = estimate(recording, calibrated())
    online = OnlineEstimator(calibrated(), 1e-3)
    for k in range(recording.n_samples):
        online.update(recording.t[k], recording.theta[k], recording.force[k], recording.torque[k])
    assert comparable(online.finalize()) == comparable(offline)


def test_human_output_says_best_guess_for_doubtful_estimates() -> None:
    recording = synthetic_recording(Synthetic(x_c=0.3, deflection_ratio=0.02, seed=11))
    wrong = estimate(recording, load_antenna("paper-2021-calibrated"))
    text = summary("rec.csv", wrong.to_dict())
    assert "best guess, not confirmed: see the status" in text
    assert text.count(wrong.reason or "") == 1  # the reason once, on the status line
    right = estimate(recording, calibrated())
    assert "best guess" not in summary("rec.csv", right.to_dict())
    assert wrong.to_dict()["x_c"] == wrong.x_c  # JSON keeps the best guess


def _glitched(column: int, value: float, count: int = 1, after_t1: float = 0.05) -> Recording:
    """A clean synthetic push at 0.5 m with ``count`` load samples from ``after_t1`` (s) after
    t_1 set to ``value``."""
    recording = synthetic_recording(Synthetic(x_c=0.5, seed=4))
    clean = estimate(recording, calibrated())
    assert clean.status is Status.OK, clean.reason
    k = int(np.searchsorted(recording.t, clean.t_1 + after_t1))
    loads = np.hstack([recording.force, recording.torque])
    loads[k : k + count, column] = value
    return Recording(t=recording.t, theta=recording.theta, force=loads[:, :3], torque=loads[:, 3:])


def _streamed(
    recording: Recording,
    block: int,
    loads: np.ndarray | None = None,
    antenna: Antenna | None = None,
) -> ContactEstimate:
    """The paper method's estimate of ``recording`` fed to a stream ``block`` samples at a time,
    with ``loads`` (n, 6; samples a recording refuses, such as inf) for its wrench if given, by
    ``antenna`` (the calibrated model by default)."""
    wrench = np.hstack([recording.force, recording.torque]) if loads is None else loads
    model = calibrated() if antenna is None else antenna
    online = OnlineEstimator(model, recording.sample_period, "paper")
    for a in range(0, recording.n_samples, block):
        b = a + block
        result = online.update_block(
            recording.t[a:b], recording.theta[a:b], wrench[a:b, :3], wrench[a:b, 3:]
        )
        if result is not None:
            return result
    return online.finalize()


def _streamed_as_offline(recording: Recording) -> None:
    """The paper method's status, reason and x_c on ``recording`` are the same streamed one
    sample at a time, 64 at a time, and offline."""
    offline = estimate(recording, calibrated(), "paper")
    for block in (1, 64):
        streamed = _streamed(recording, block)
        assert (streamed.status, streamed.reason, streamed.x_c) == (
            offline.status,
            offline.reason,
            offline.x_c,
        ), block


@pytest.mark.parametrize("column", [1, 4])  # fy, ty: the push's force and its moment
@pytest.mark.parametrize("value", [1e300, -1.7976931348623157e308])
def test_a_glitch_beyond_any_sensor_in_the_hold_gives_a_status_without_warnings(
    column: int, value: float
) -> None:
    # Samples of 1e300 N (or N m) after t_1, where the hold, the ratio and the spectrum read,
    # more in a row than the front end puts back: sums, norms, the ratio's fixed point
    # overflow. The suite runs with warnings as errors, so a NumPy warning here (lines on a
    # user's terminal) fails the test. Found by the fuzz suite.
    glitched = _glitched(column, value, count=SPIKE_LONGEST + 2)
    for method in ("paper", "ratio", "two-frequency", "fast"):
        result = estimate(glitched, calibrated(), method)
        assert result.status is not Status.OK, (method, result.x_c)
        assert math.isnan(result.x_c) or 0.0 < result.x_c <= 0.98
        assert "repaired_samples" not in result.diagnostics


@pytest.mark.parametrize(
    ("column", "value"),
    [(1, 1e300), (1, -1.7976931348623157e308), (1, 0.5), (4, 1e300), (4, -0.3), (4, 0.0)],
)
@pytest.mark.parametrize(
    ("count", "after_t1"),
    [(1, 0.05), (2, 0.05), (5, 0.05), (SPIKE_LONGEST, 0.05), (SPIKE_LONGEST, -0.5)],
)
def test_a_run_of_corrupted_samples_is_put_back_and_named(
    column: int, value: float, count: int, after_t1: float
) -> None:
    # A sensor bus's glitch: one sample (or a run of them) of one channel far off, or zero,
    # between calm neighbours (a force at least twice the link's weight off, a torque half its
    # weight's moment: the link's own impacts ring single samples below that), in the
    # estimation window or at rest. The front end puts it back on the line between them and
    # says so; the estimate is the clean recording's, its status and x_c within 1 mm (the
    # repaired samples are the line, not the clean values: the fast method's answer may move
    # by a step or two of its 0.25 mm grid).
    glitched = _glitched(column, value, count, after_t1)
    clean = synthetic_recording(Synthetic(x_c=0.5, seed=4))
    k = int(np.flatnonzero(np.hstack([glitched.force, glitched.torque])[:, column] == value)[0])
    for method in ("paper", "ratio", "two-frequency", "fast"):
        result = estimate(glitched, calibrated(), method)
        expected = estimate(clean, calibrated(), method)
        assert result.diagnostics["repaired_samples"] == [
            {
                "t": float(glitched.t[k]),
                "samples": count,
                "channels": [("fx", "fy", "fz", "tx", "ty", "tz")[column]],
            }
        ], method
        assert result.status is expected.status, (method, result.reason)
        assert abs(result.x_c - expected.x_c) < 0.001, method
    # antenna estimate says so in one line
    line = summary("glitched.csv", result.to_dict()).splitlines()[-1]
    channel = ("fx", "fy", "fz", "tx", "ty", "tz")[column]
    assert line.startswith("  put back        sensor samples off their neighbours at ")
    assert f"s ({channel}{f', {count} samples' if count > 1 else ''})" in line


@pytest.mark.parametrize(("column", "value"), [(1, 0.5), (4, -0.3), (4, 0.0)])
@pytest.mark.parametrize(
    ("count", "after_t1"), [(SPIKE_LONGEST + 1, 0.05), (50, 0.05), (200, 0.05), (50, -0.5)]
)
def test_a_corrupted_run_too_long_to_put_back_is_bad_input_and_named(
    column: int, value: float, count: int, after_t1: float
) -> None:
    # The same glitch, longer than the front end puts back (a straight line across it would
    # make up part of a period of the vibration): the samples are not whole, every method says
    # so and why, with its best guess but no interval, and a stream says the same.
    glitched = _glitched(column, value, count, after_t1)
    k = int(np.flatnonzero(np.hstack([glitched.force, glitched.torque])[:, column] == value)[0])
    channel = ("fx", "fy", "fz", "tx", "ty", "tz")[column]
    said = f"{channel}: {count} samples in a row from t = {glitched.t[k]:.4f} s"
    for method in ("paper", "ratio", "two-frequency", "fast"):
        result = estimate(glitched, calibrated(), method)
        assert result.t_e > glitched.t[k + count], method  # the run lies before its t_e
        assert result.status is Status.BAD_INPUT, (method, result.status, result.reason)
        assert result.reason is not None and result.reason.startswith(said), result.reason
        assert result.interval is None
        assert "repaired_samples" not in result.diagnostics
    _streamed_as_offline(glitched)


@pytest.mark.parametrize("value", [math.inf, 1e308])
def test_a_long_run_of_samples_beyond_floats_in_a_stream_is_named_without_warnings(
    value: float,
) -> None:
    # A stream takes samples a recording refuses (inf); thirty in a row of the push's force,
    # sample by sample (the suite turns NumPy's warnings into errors): the run is named.
    glitched = _glitched(1, 0.5, 30)
    loads = np.hstack([glitched.force, glitched.torque])
    k = int(np.flatnonzero(loads[:, 1] == 0.5)[0])
    loads[k : k + 30, 1] = value
    result = _streamed(glitched, 1, loads)
    assert result.status is Status.BAD_INPUT
    assert (result.reason or "").startswith(
        f"fy: 30 samples in a row from t = {glitched.t[k]:.4f} s"
    )


def _stalled(count: int, after_t1: float) -> tuple[Recording, int]:
    """A clean synthetic push at 0.5 m whose sensor stalls ``after_t1`` (s) after t_1: the
    reading before repeated ``count`` times on all six channels; and that reading's index."""
    recording = synthetic_recording(Synthetic(x_c=0.5, seed=4))
    clean = estimate(recording, calibrated())
    k = int(np.searchsorted(recording.t, clean.t_1 + after_t1))
    loads = np.hstack([recording.force, recording.torque])
    loads[k : k + count] = loads[k - 1]
    stalled = Recording(
        t=recording.t, theta=recording.theta, force=loads[:, :3], torque=loads[:, 3:]
    )
    return stalled, k - 1


@pytest.mark.parametrize(("count", "after_t1"), [(GAP_LIMIT, 0.05), (300, 0.05), (60, -0.05)])
def test_a_stalled_sensor_repeating_its_reading_is_bad_input_and_named(
    count: int, after_t1: float
) -> None:
    # A driver that stalls and sends the sensor's last reading again: the time stamps go on,
    # all six channels stand still while the link rings. Longer than the gaps a recording may
    # have (the reading itself and its repeats), it is named for every method, in a stream too.
    stalled, k = _stalled(count, after_t1)
    _named_for_every_method(stalled, k, count)


def test_a_contact_made_while_the_sensor_stood_still_is_named() -> None:
    # The sensor stalls for 0.3 s of the sweep, during which the link touches a post at 0.95 m:
    # the contact is found when the readings move again, just after the run, which is named.
    antenna = load_antenna("paper-2021")
    recording = simulate(antenna, Scenario(case="azimuthal", contact_point=0.95, seed=950))
    loads = np.hstack([recording.force, recording.torque])
    k = int(np.searchsorted(recording.t, 0.914 - 1e-9))
    loads[k + 1 : k + 301] = loads[k]
    stalled = dataclasses.replace(recording, force=loads[:, :3], torque=loads[:, 3:])
    said = f"fx, fy, fz, tx, ty, tz: 301 samples in a row from t = {recording.t[k]:.4f} s hold"
    for method in ("paper", "fast"):
        result = estimate(stalled, antenna.self_calibrated(), method)
        assert result.t_c > recording.t[k + 300]
        assert result.status is Status.BAD_INPUT, (method, result.status, result.reason)
        assert (result.reason or "").startswith(said), result.reason


def _named_for_every_method(stalled: Recording, k: int, count: int) -> None:
    """Every method's answer on ``stalled`` is bad input naming the held run from sample ``k``,
    and a stream says so as offline."""
    said = (
        f"fx, fy, fz, tx, ty, tz: {count + 1} samples in a row from t = {stalled.t[k]:.4f} s "
        "hold one value"
    )
    for method in ("paper", "ratio", "two-frequency", "fast"):
        result = estimate(stalled, calibrated(), method)
        assert result.status is Status.BAD_INPUT, (method, result.status, result.reason)
        assert (result.reason or "").startswith(said), result.reason
        assert result.interval is None
    _streamed_as_offline(stalled)


def test_a_channel_zeroed_through_a_slow_ringing_is_bad_input_and_named() -> None:
    # The push's force zeroed for 100 samples at a contact near the head (0.3 m), whose
    # ringing (about 4.5 Hz) moves the level by more than the run's height meanwhile: no level
    # to come back to, but one value held where the channel moves on both sides.
    antenna = load_antenna("paper-2021")
    recording = simulate(antenna, Scenario(case="azimuthal", contact_point=0.3, seed=300))
    loads = np.hstack([recording.force, recording.torque])
    k = int(np.searchsorted(recording.t, 1.63 - 1e-9))
    loads[k : k + 100, 1] = 0.0
    zeroed = dataclasses.replace(recording, force=loads[:, :3], torque=loads[:, 3:])
    judged = []
    for method in ("paper", "fast"):
        result = estimate(zeroed, antenna.self_calibrated(), method)
        if result.t_e < recording.t[k]:
            continue  # answered before the run
        judged.append(method)
        assert result.status is Status.BAD_INPUT, (method, result.status, result.reason)
        assert (result.reason or "").startswith(
            f"fy: 100 samples in a row from t = {recording.t[k]:.4f} s hold one value"
        )
    assert "paper" in judged  # its t_e is t_1 + 1 s


@pytest.mark.parametrize(("count", "after_t1"), [(GAP_LIMIT - 1, 0.05), (100, -0.6)])
def test_a_stall_as_short_as_a_gap_or_before_the_contact_is_not_named(
    count: int, after_t1: float
) -> None:
    # As many samples in a row as a gap may miss (the reading and its repeats), or a stall
    # during the free sweep that ends before the contact: not named.
    stalled, k = _stalled(count, after_t1)
    for method in ("paper", "fast"):
        result = estimate(stalled, calibrated(), method)
        assert result.t_c > stalled.t[k + count] or count < GAP_LIMIT
        assert "hold one value" not in (result.reason or ""), result.reason


@pytest.mark.parametrize(("case", "x_c"), [("vertical", 0.3), ("azimuthal", 0.9)])
def test_a_sensor_read_to_its_resolution_is_not_taken_for_a_stall(case: str, x_c: float) -> None:
    # A real sensor's readings are whole counts of its resolution: with its noise about a
    # count, a quiet stretch repeats one channel's reading now and then, never all six over
    # more samples than a gap. The slow ringing at 0.3 m and the quiet hold at 0.9 m.
    antenna = load_antenna("paper-2021")
    recording = simulate(antenna, Scenario(case=case, contact_point=x_c, seed=5))
    counts = np.array(ATI_NANO17_RESOLUTION)
    loads = np.round(np.hstack([recording.force, recording.torque]) / counts) * counts
    read = dataclasses.replace(recording, force=loads[:, :3], torque=loads[:, 3:])
    for method in ("paper", "fast"):
        result = estimate(read, antenna.self_calibrated(), method)
        assert result.status is not Status.BAD_INPUT, (method, result.reason)


def _restamped(recording: Recording, share: float, seed: int) -> Recording:
    """``recording`` with ``share`` of its samples, drawn at random, sent twice in a row (every
    column) and every sample stamped by its count at the recording's period: a logger that
    takes a reading sent again for a new one."""
    n = recording.t.size
    twice = np.random.default_rng(seed).choice(np.arange(1, n), round(share * n), replace=False)
    rows = np.sort(np.concatenate([np.arange(n), twice]))
    period = float(recording.metadata["sample_period"])
    return dataclasses.replace(
        recording,
        t=np.arange(rows.size) * period,
        theta=recording.theta[rows],
        force=recording.force[rows],
        torque=recording.torque[rows],
        extra={},
    )


@pytest.mark.parametrize(("case", "x_c"), [("azimuthal", 0.75), ("vertical", 0.95)])
def test_readings_sent_again_and_stamped_as_new_are_not_an_ok_answer(case: str, x_c: float) -> None:
    # 5 % of the readings sent twice, stamped by count: the record's time runs 5 % long and
    # omega_1 reads 5 % low, which the curve's top (0.75 m) and its falling end (0.95 m) turn
    # into centimetres while omega_2 / omega_1 and the statics stay as they were. No single
    # repeat is a stall; together they are beyond chance for a ringing link's six channels.
    antenna = load_antenna("paper-2021-calibrated")
    recording = simulate(antenna, Scenario(case=case, contact_point=x_c, seed=1))
    restamped = _restamped(recording, 0.05, seed=101)
    for method in ("paper", "fast"):
        result = estimate(restamped, antenna, method)
        assert result.status is not Status.OK, (method, result.x_c)
        repeats = result.diagnostics.get("repeated_rows")
        if result.status is Status.UNCERTAIN and "repeat the one before" in (result.reason or ""):
            # the share counted from t_1 to t_e is the 5 % sent twice: about 1000 steps, a
            # binomial spread of 0.7 %, within three of it; none taken for a lost reading
            assert repeats is not None and not repeats["in_place"]
            assert repeats["count"] / repeats["steps"] == pytest.approx(0.05, abs=0.021)
    offline = estimate(restamped, antenna, "paper")
    said = [offline.reason or "", *offline.diagnostics.get("other_reasons", [])]
    assert any("repeat the one before in all six channels" in text for text in said), said
    for block in (1, 64):
        streamed = _streamed(restamped, block, antenna=antenna)
        assert (streamed.status, streamed.reason) == (offline.status, offline.reason)


@pytest.mark.parametrize(
    "wrench",
    [np.zeros((0, 6)), np.zeros((1, 6)), np.ones((50, 6)), np.full((50, 6), np.nan)],
    ids=["empty", "one row", "still", "not a number"],
)
def test_repeats_are_not_judged_without_a_ringing_to_judge_them_by(wrench: np.ndarray) -> None:
    assert repeated_rows(wrench) is None
    assert repeated_rows(wrench, first=1000) is None


@pytest.mark.parametrize("kind", ["in place of lost readings", "gauges read coarsely"])
def test_repeats_the_time_base_does_not_explain_are_not_taken_for_a_stretch(kind: str) -> None:
    # Readings sent again in place of lost ones keep the stamps right; a sensor whose six
    # outputs mix gauges read to four counts repeats all six wherever every gauge stands still
    # (about 6 % of the samples here). Neither stretches the time.
    antenna = load_antenna("paper-2021-calibrated")
    recording = simulate(antenna, Scenario(case="vertical", contact_point=0.3, seed=1))
    loads = np.hstack([recording.force, recording.torque])
    if kind == "in place of lost readings":
        n = recording.t.size
        lost = np.sort(np.random.default_rng(101).choice(np.arange(1, n), n // 20, replace=False))
        rows = np.arange(n)
        for k in lost:
            rows[k] = rows[k - 1]
        loads = loads[rows]
    else:
        counts = 4.0 * np.array(ATI_NANO17_RESOLUTION)
        mixing = np.eye(6) + 0.3 * np.linalg.qr(np.random.default_rng(0).normal(size=(6, 6)))[0]
        gauges = np.round(loads / counts @ np.linalg.inv(mixing).T)
        loads = gauges @ mixing.T * counts
    read = dataclasses.replace(recording, force=loads[:, :3], torque=loads[:, 3:])
    result = estimate(read, antenna, "paper")
    said = [result.reason or "", *result.diagnostics.get("other_reasons", [])]
    assert not any("repeat the one before" in text for text in said), said
    assert abs(result.x_c - float(recording.metadata["true_xc"])) < 2e-3


def test_a_few_readings_sent_again_leave_the_answer_alone() -> None:
    # Two in a thousand: too few to stretch the time by what moves the answer, or to tell
    # from chance; the answer is the clean recording's within the shift they could make.
    antenna = load_antenna("paper-2021-calibrated")
    recording = simulate(antenna, Scenario(case="azimuthal", contact_point=0.55, seed=1))
    clean = estimate(recording, antenna, "paper")
    result = estimate(_restamped(recording, 0.002, seed=101), antenna, "paper")
    assert clean.status is Status.OK
    assert result.status is Status.OK, result.reason
    assert result.x_c == pytest.approx(clean.x_c, abs=2e-3)


@pytest.mark.parametrize(("jitter", "misplaced"), [(0.3e-3, False), (0.45e-3, True)])
def test_a_stream_whose_stamps_jitter_by_half_a_period_is_bad_input(
    jitter: float, misplaced: bool
) -> None:
    # A host that stamps the samples as they arrive: within +-0.3 ms each finds its place on
    # the 1 ms grid; at +-0.45 ms a tenth come for a place another took (left out, the places
    # put back), the readings sit up to a period off, and omega_1 moved the answer 3 to 11 mm
    # (the fast method's interval missing the contact). A new user's walk got ok there.
    antenna = load_antenna("paper-2021-calibrated")
    recording = simulate(antenna, Scenario(case="azimuthal", contact_point=0.55, seed=1))
    stamps = recording.t + np.random.default_rng(2).uniform(-jitter, jitter, recording.t.size)
    online = OnlineEstimator(antenna, 1e-3, "paper")
    result = None
    for k in range(recording.t.size):
        args = (stamps[k], recording.theta[k], recording.force[k], recording.torque[k])
        result = online.update(*args)
        if result is not None:
            break
    result = result or online.finalize()
    if misplaced:
        assert result.status is Status.BAD_INPUT, (result.status, result.reason)
        assert "came for a place on the period's grid that another had taken" in (
            result.reason or ""
        )
    else:
        assert result.status is Status.OK, result.reason
        assert result.x_c == pytest.approx(float(recording.metadata["true_xc"]), abs=1e-3)


@pytest.mark.parametrize("after_t1", [0.05, -0.5])
@pytest.mark.parametrize("block", [1, 64])
def test_a_sample_that_is_not_a_number_ends_a_stream_as_bad_input(
    after_t1: float, block: int
) -> None:
    # A driver in the loop that hands over NaN for a reading it did not get: a recording with
    # one is refused, and a stream ends with bad input naming the column and the instant, not
    # with a reason the NaN made up (a sign flipped, a ratio that did not settle).
    glitched = _glitched(1, 0.5, 1, after_t1)
    loads = np.hstack([glitched.force, glitched.torque])
    k = int(np.flatnonzero(loads[:, 1] == 0.5)[0])
    loads[k, 1] = math.nan
    result = _streamed(glitched, block, loads)
    assert result.status is Status.BAD_INPUT
    assert result.reason == (
        f"column 'fy': not a number (NaN) at t = {glitched.t[k]:.4f} s, a reading the device "
        "did not give; a sample's values must all be numbers, its time stamp finite"
    )


def test_a_stream_stamped_in_milliseconds_is_told_so() -> None:
    # a driver's stamps in ms fed to an estimator of a 1 ms period: each step is a gap of 999
    # samples, and the reason says what such a gap most likely is
    recording = simulate(paper_antenna(), Scenario(case="azimuthal", contact_point=0.55, seed=2))
    online = OnlineEstimator(paper_antenna(), recording.sample_period)
    result = None
    for k in range(recording.n_samples):
        stamp = 1000.0 * float(recording.t[k])
        result = online.update(stamp, recording.theta[k], recording.force[k], recording.torque[k])
        if result is not None:
            break
    result = result if result is not None else online.finalize()
    assert result.status is Status.BAD_INPUT
    assert (result.reason or "").startswith(
        "sample_period: declared 0.001 s, but its time stamps step by 1 s"
    )
    assert " (time stamps in ms? the format's are in s)" in (result.reason or "")


def test_a_stream_at_another_period_than_declared_is_bad_input() -> None:
    # a 500 Hz loop's samples fed to an estimator built for 1 kHz: every step would be a sample
    # put back, and the filters built for 1 kHz. The first twenty steps say so; built for the
    # samples' period, the same samples are read
    antenna = calibrated()
    scenario = Scenario(case="azimuthal", contact_point=0.5, seed=2, sample_period=2e-3)
    recording = simulate(antenna, scenario)

    def fed(period: float, count: int) -> ContactEstimate:
        online = OnlineEstimator(antenna, period)
        for k in range(count):
            result = online.update(
                recording.t[k], recording.theta[k], recording.force[k], recording.torque[k]
            )
            if result is not None:
                return result
        return online.finalize()

    wrong = fed(1e-3, recording.n_samples)
    assert wrong.status is Status.BAD_INPUT
    assert wrong.reason == (
        "sample_period: declared 0.001 s, but its time stamps step by 0.002 s (the median of its"
        " first 20 steps), more than 2 % apart: the estimates need the period the samples have"
    )
    assert wrong.t_c != wrong.t_c  # refused at the twentieth step, long before any contact
    short = fed(1e-3, 10)  # a stream that ends first is judged on the steps it has
    assert short.status is Status.BAD_INPUT
    assert (short.reason or "").startswith("sample_period: declared 0.001 s, but its time stamps")
    assert fed(2e-3, recording.n_samples).ok


def test_a_stream_a_few_per_cent_off_its_declared_period_is_bad_input_at_the_estimate() -> None:
    # a loop that samples at 982 Hz but declares 1 ms, its stamps jittering by +-0.2 ms: the
    # first twenty stamps' line cannot tell 1.8 % from their jitter, and the estimate read on a
    # 1 ms period was `ok` 5 mm off; a line through every stamp up to the estimate can
    antenna = calibrated()
    rng = np.random.default_rng(1)

    def fed(recording: Recording) -> ContactEstimate:
        online = OnlineEstimator(antenna, 1e-3, method="fast")
        stamps = recording.t + rng.uniform(-2e-4, 2e-4, recording.n_samples)
        for k in range(recording.n_samples):
            result = online.update(
                stamps[k], recording.theta[k], recording.force[k], recording.torque[k]
            )
            if result is not None:
                return result
        return online.finalize()

    slow = simulate(
        antenna, Scenario(case="azimuthal", contact_point=0.55, seed=3, sample_period=1 / 982)
    )
    wrong = fed(slow)
    assert wrong.status is Status.BAD_INPUT
    assert (wrong.reason or "").startswith("sample_period: declared 0.001 s, but a line through")
    assert "(+1.8" in (wrong.reason or "")
    # the same jitter on a loop that does sample at 1 kHz passes
    assert fed(simulate(antenna, Scenario(case="azimuthal", contact_point=0.55, seed=3))).ok


def test_stamps_off_the_declared_period_by_the_clock_tolerance_are_taken() -> None:
    # the file's rule: stamps within CLOCK_TOLERANCE (0.1 %) of the period are trusted. Exactly
    # 0.1 % off, they were refused by the stamps' last bit, "more than 0.1 % apart"
    start = 5.0 + np.arange(21)
    assert declared_period_problem(1.001e-3 * start, 1e-3) is None
    assert declared_period_problem(0.999e-3 * start, 1e-3) is None
    assert "more than 0.1 % apart" in str(declared_period_problem(1.0011e-3 * start, 1e-3))


@pytest.mark.parametrize("stamp", [math.inf, -math.inf])
def test_an_infinite_time_stamp_ends_a_stream_as_bad_input(stamp: float) -> None:
    # a stamp with no place in time ends the stream as a NaN does (it was taken for the next
    # sample, and the answer went on as if nothing happened)
    recording = simulate(paper_antenna(), Scenario(case="azimuthal", contact_point=0.55, seed=2))
    online = OnlineEstimator(paper_antenna(), recording.sample_period)
    result = None
    for k in range(recording.n_samples):
        t = stamp if k == 1500 else float(recording.t[k])
        result = online.update(t, recording.theta[k], recording.force[k], recording.torque[k])
        if result is not None:
            break
    assert result is not None and result.status is Status.BAD_INPUT
    assert (result.reason or "").startswith(
        f"column 't': infinite after t = {recording.t[1499]:.4f} s"
    )


def test_a_contact_lost_and_found_again_is_not_taken_for_a_corrupted_run() -> None:
    # A fast sweep into a stiff bar on the nonlinear link: during the push fx leaves its level
    # for 30 samples and comes back, as a corrupted run would (the friction along the link
    # turns); the reaction along the hold's, mostly that axial part, falls to 0.38 of the push
    # before meanwhile, so it is taken for a rebound, and no reason blames the sensor.
    antenna = load_antenna("paper-2021")
    scenario = Scenario(
        case="vertical",
        contact_point=0.7325831481310732,
        contact_stiffness=1e5,
        seed=820075,
        push=PushCriterion(threshold=0.1),
        link_model="nonlinear",
        sweep_speed=1.5,
        accel_time=0.05,
    )
    recording = simulate(antenna, scenario)
    # the loss, near 0.513 s (the sample it falls on moves with the platform's floating point)
    around = recording.force[(recording.t > 0.505) & (recording.t < 0.52), 0]
    assert around.min() < -0.1 < 0.0 < around.max()
    for method in ("paper", "fast"):
        result = estimate(recording, antenna.self_calibrated(), method)
        reasons = [result.reason or "", *result.diagnostics.get("other_reasons", [])]
        assert not any("like a corrupted run" in reason for reason in reasons), reasons


def test_runs_in_two_channels_that_overlap_are_each_put_back() -> None:
    # The bus corrupts the push's force for three samples and, from the second of them, its
    # moment for two: each channel's run is put back, and the estimate is the clean one's.
    recording = synthetic_recording(Synthetic(x_c=0.5, seed=4))
    clean = estimate(recording, calibrated())
    k = int(np.searchsorted(recording.t, clean.t_1 + 0.05))
    loads = np.hstack([recording.force, recording.torque])
    loads[k : k + 3, 1] = 1e3
    loads[k + 1 : k + 3, 4] = -50.0
    glitched = Recording(
        t=recording.t, theta=recording.theta, force=loads[:, :3], torque=loads[:, 3:]
    )
    result = estimate(glitched, calibrated())
    assert result.diagnostics["repaired_samples"] == [
        {"t": float(recording.t[k]), "samples": 3, "channels": ["fy"]},
        {"t": float(recording.t[k + 1]), "samples": 2, "channels": ["ty"]},
    ]
    assert result.status is clean.status
    assert abs(result.x_c - clean.x_c) < 0.001
    # a stream that waits for the second run's samples decides as the whole recording does
    for block in (1, 7, 64):
        streamed = _streamed(glitched, block)
        assert (streamed.status, streamed.x_c) == (result.status, result.x_c), block
        assert streamed.diagnostics["repaired_samples"] == result.diagnostics["repaired_samples"]


def test_a_corrupted_sample_is_put_back_in_a_stream_as_offline() -> None:
    # The stream holds a suspect back until the samples that decide it have come: the same
    # estimate, to the bit, whatever the blocks.
    glitched = _glitched(4, -3.0, SPIKE_LONGEST, -0.5)
    offline = estimate(glitched, calibrated(), "paper")
    assert offline.status is Status.OK
    assert offline.diagnostics["repaired_samples"]
    for block in (1, 5, 64):
        result = _streamed(glitched, block)
        assert result.status is offline.status
        assert result.x_c == offline.x_c
        assert result.diagnostics["repaired_samples"] == offline.diagnostics["repaired_samples"]


@pytest.mark.parametrize("column", [1, 4])
@pytest.mark.parametrize("value", [1e100, 1e155])
def test_a_glitch_whose_square_overflows_gives_an_answer_not_a_traceback(
    column: int, value: float
) -> None:
    # Smaller glitches than the one above still overflow a square (the frequency's standard
    # deviation) or the statics' model term (NaN): the estimate comes back, without warnings,
    # and an `ok` lies within the fast method's 5 mm tolerance of the contact.
    glitched = _glitched(column, value)
    for method in ("paper", "ratio", "two-frequency", "fast"):
        result = estimate(glitched, calibrated(), method)
        assert result.status is not Status.OK or abs(result.x_c - 0.5) < 0.005, method


def test_a_pencil_pole_that_grows_beyond_floats_gives_an_answer_not_a_traceback() -> None:
    # Every channel at 10^4 times its largest value for 21 samples, in the vibration window of
    # a simulated vertical contact: the fast method's pencil returns a pole whose envelope
    # overflows over the window; it is left out, and the run is named.
    antenna = load_antenna("paper-2021")
    clean = simulate(antenna, Scenario(case="vertical", contact_point=0.40, seed=407))
    loads = np.hstack([clean.force, clean.torque])
    loads[1630:1651] = 1e4 * np.max(np.abs(loads), axis=0)
    glitched = Recording(t=clean.t, theta=clean.theta, force=loads[:, :3], torque=loads[:, 3:])
    result = estimate(glitched, antenna.self_calibrated(), "fast")
    assert result.status is Status.BAD_INPUT, result.reason
    assert "21 samples in a row from t = 1.6300 s" in (result.reason or "")


def test_a_ratio_that_overflows_is_no_reading() -> None:
    # Torques scaled far beyond any device (1e300, 8e5: 1.8e4 N m for the link's weight)
    # overflow Eq. 21 and its fixed point to inf; ContactEstimate.ratio_estimate is a length or
    # NaN, never inf (the JSON writes null for both). Found by the fuzz suite on a simulated
    # manoeuvre (the synthetic one's ratio stays NaN).
    from sensing_antenna.simulator import Scenario, simulate

    recording = simulate(calibrated(), Scenario(case="azimuthal", contact_point=0.4, seed=1))
    for torque_scale in (1e300, 8e5):
        scaled = Recording(
            t=recording.t,
            theta=recording.theta,
            force=recording.force,
            torque=recording.torque * torque_scale,
        )
        for method in ("paper", "ratio", "two-frequency", "fast"):
            result = estimate(scaled, calibrated(), method)
            assert result.status is Status.IMPLAUSIBLE_INPUT
            ratio = result.ratio_estimate
            assert math.isfinite(ratio) or math.isnan(ratio), (method, torque_scale)


def test_a_second_mode_against_the_ratios_branch_is_a_disagreement() -> None:
    # Forces read 3 % high and torques 3 % low (a sensor's gain errors, docs/simulator.md): the
    # ratio reads 6 % short, 0.758 m for a contact at 0.792 m near the top of the sensing curve,
    # and is closer to the other branch's candidate (0.746 m); its uncertainty there (7 cm) is
    # too wide to choose, and the second mode is not clear enough to choose by (quality 13.5,
    # under 20), but it lies in the other candidate's omega_2 window, ten times stronger than in
    # the chosen one's: the two estimators disagree, where the method said ok 4.6 cm off.
    from sensing_antenna.simulator import Scenario, simulate
    from sensing_antenna.simulator.device import DeviceImperfections

    gains = DeviceImperfections(sensor_gain=(1.03, 1.03, 1.03, 0.97, 0.97, 0.97))
    recording = simulate(
        paper_antenna(), Scenario(case="vertical", contact_point=0.8, seed=2807, device=gains)
    )
    truth = float(recording.metadata["true_xc"])
    result = estimate(recording.without_ground_truth(), calibrated(), "paper")
    assert abs(result.x_c - truth) > 0.04
    assert result.status is Status.ESTIMATORS_DISAGREE
    assert "second contact mode" in (result.reason or "")


def test_a_spike_after_two_inf_samples_is_put_back_sample_by_sample_as_in_blocks() -> None:
    # Two inf samples in a row (put back themselves) make an inf - inf step, no number; the
    # stream's per-sample path must still judge the spike 50 samples later, as a block does.
    glitched = _glitched(4, -3.0)
    loads = np.hstack([glitched.force, glitched.torque])
    loads[100:102, 1] = np.inf
    loads[150, 1] += 5.0
    results = [_streamed(glitched, block, loads) for block in (1, 7, glitched.n_samples)]
    for result in results:
        assert result.status is results[-1].status and result.x_c == results[-1].x_c
        times = [r["t"] for r in result.diagnostics["repaired_samples"]]
        assert times[:2] == [float(glitched.t[100]), float(glitched.t[150])]


def test_a_ratio_that_moves_after_settling_names_a_drifting_force_offset_beside_a_slide() -> None:
    # A force offset that ramps by 4 mN/s from 0.3 s after t_1 under a push of about 30 mN at
    # 0.9 m moves the settled ratio by 4 cm: not told from a slide along the link, the reason
    # says how large an offset would do it, to set beside the sensor's drift
    antenna = calibrated()
    scenario = Scenario(case="azimuthal", contact_point=0.9, seed=2)
    recording = simulate(antenna, scenario).without_ground_truth()
    plain = estimate(recording, antenna, "paper")
    assert plain.ok, plain.reason
    force = recording.force.copy()
    force[:, 1] += 4e-3 * np.clip(recording.t - (plain.t_1 + 0.3), 0.0, None)
    drifted = estimate(dataclasses.replace(recording, force=force), antenna, "paper")
    assert drifted.status is Status.SLIP_SUSPECTED, drifted.reason
    reason = drifted.reason or ""
    assert "the contact sliding along the link, or the sensor's force offset drifting by" in reason
    said = float(reason.split("drifting by ")[1].split(" mN")[0])
    # the offset at t_e (2.8 mN) against what the ratio's moving mean over its window saw
    assert 0.5 < said < 2.8
