"""Two timed streams onto one uniform clock: the wrench at its own samples, the joints
interpolated, gaps left out. References are streams built here whose right answer is known: a
ramp, which linear interpolation gives back exactly, and gaps placed by hand."""

from __future__ import annotations

import numpy as np
import pytest

from sensing_antenna.importers import ImporterError
from sensing_antenna.importers.clock import Stream, put_on_clock

EPOCH_NS = 1_700_000_000_000_000_000
MS = 1_000_000  # ns


def _wrench(n: int, period_ns: int = MS, start_ns: int = EPOCH_NS) -> Stream:
    """A 1 kHz wrench whose six values at sample k are k, 2k, ... 6k."""
    k = np.arange(n)
    return Stream(
        name="/wrench",
        kind="wrench",
        stamps=start_ns + k.astype(np.int64) * period_ns,
        values=np.outer(k, np.arange(1, 7)).astype(np.float64),
    )


def _ramp_joints(stamps: np.ndarray) -> Stream:
    """Joints at the given stamps (ns): theta1 = 0.3 rad/s x t, theta2 = 0.1 - 0.2 rad/s x t."""
    t = (stamps - EPOCH_NS) / 1e9
    return Stream(
        name="/joints",
        kind="joints",
        stamps=stamps,
        values=np.column_stack([0.3 * t, 0.1 - 0.2 * t]),
    )


def test_slower_joints_are_interpolated_linearly_and_the_wrench_kept_as_sampled() -> None:
    wrench = _wrench(1001)
    joints = _ramp_joints(EPOCH_NS + np.arange(201, dtype=np.int64) * 5 * MS)  # 200 Hz
    clocked = put_on_clock(wrench, joints, source="log")
    report = clocked.report
    assert report.period == 0.001 and report.n_samples == 1001
    assert report.joints.rate == 200.0 and report.wrench.rate == 1000.0
    np.testing.assert_array_equal(clocked.t, np.arange(1001) * 0.001)
    np.testing.assert_array_equal(clocked.wrench, wrench.values)
    expected = np.column_stack([0.3 * clocked.t, 0.1 - 0.2 * clocked.t])
    np.testing.assert_allclose(clocked.joints, expected, rtol=0, atol=1e-15)  # a ramp, exactly


def test_a_clock_faster_than_the_sensor_interpolates_the_samples_between() -> None:
    wrench = _wrench(101)
    joints = _ramp_joints(wrench.stamps)
    clocked = put_on_clock(wrench, joints, source="log", period=0.0005)
    assert clocked.report.n_samples == 201 and clocked.report.n_interpolated == 100
    np.testing.assert_array_equal(clocked.wrench[::2], wrench.values)
    np.testing.assert_allclose(clocked.wrench[1::2], (wrench.values[1:] + wrench.values[:-1]) / 2)


def test_motor_commands_are_held_from_each_to_the_next_and_start_the_clock() -> None:
    # a program that sends a new command every 10 ms, 2.5 ms after the sensor's ticks, from
    # 30 ms on: each slot carries the last command sent at or before it, and the clock begins
    # at the first slot after the first command
    wrench = _wrench(201)
    joints = _ramp_joints(wrench.stamps)
    stamps = EPOCH_NS + 30 * MS + MS // 2 * 5 + np.arange(17, dtype=np.int64) * 10 * MS
    volts = np.column_stack([np.arange(17.0), -np.arange(17.0)])
    clocked = put_on_clock(
        wrench, joints, source="log", commands=Stream("/servo", "commands", stamps, volts)
    )
    assert clocked.commands is not None
    assert clocked.report.origin_ns == int(wrench.stamps[33])  # 32.5 ms: the next tick
    slots = clocked.report.origin_ns + np.rint(clocked.t * 1e9).astype(np.int64)
    sent = (slots - stamps[0]) // (10 * MS)  # the command in force at each slot
    np.testing.assert_array_equal(clocked.commands, volts[np.minimum(sent, 16)])
    assert put_on_clock(wrench, joints, source="log").commands is None
    # commands that begin after the other two end are named, not the two
    late = Stream("/servo", "commands", stamps + 500 * MS, volts)
    with pytest.raises(ImporterError, match=r"'/servo' \(.*\) begins after the wrench and"):
        put_on_clock(wrench, joints, source="log", commands=late)


def test_the_clock_covers_only_the_time_both_streams_cover() -> None:
    wrench = _wrench(100)
    joints = _ramp_joints(EPOCH_NS + np.arange(20, 80, dtype=np.int64) * MS + MS // 3)
    clocked = put_on_clock(wrench, joints, source="log")
    # from the first wrench message after the joints start (sample 21) to the joints' end
    assert clocked.report.origin_ns == int(wrench.stamps[21])
    np.testing.assert_array_equal(clocked.wrench[0], wrench.values[21])
    assert clocked.t[-1] == pytest.approx((79 - 21) * 0.001)


def test_slots_inside_a_joint_gap_are_left_out() -> None:
    wrench = _wrench(200)
    stamps = EPOCH_NS + np.arange(200, dtype=np.int64) * MS
    joints = _ramp_joints(np.delete(stamps, np.arange(50, 80)))  # 31 ms between 49 and 80
    clocked = put_on_clock(wrench, joints, source="log")
    assert clocked.report.joints.n_gaps == 1 and clocked.report.n_left_out == 30
    kept = np.rint(clocked.t / 0.001).astype(int)
    assert set(range(200)) - set(kept) == set(range(50, 80))
    gap = put_on_clock(wrench, joints, source="log", max_gap=32.0)
    assert gap.report.n_left_out == 0 and gap.report.joints.n_gaps == 0


@pytest.mark.parametrize("period_ms", [1, 2, 4])
def test_the_default_gap_is_the_estimators_20_ms_at_the_clock_s_rate(period_ms: int) -> None:
    # a wrench at 1 kHz, 500 Hz or 250 Hz and joints at 100 Hz (10 ms): by default a silence
    # of more than 20 ms is a gap in either stream, whatever its own rate, as the estimators
    # refuse after the push; one of 20 ms is bridged
    n = 2000 // period_ms
    wrench = _wrench(n, period_ns=period_ms * MS)
    allowed = 20 // period_ms  # samples of the clock in 20 ms
    lost = np.arange(100, 100 + allowed + 1)  # one more: a gap
    joints = _ramp_joints(EPOCH_NS + np.delete(np.arange(0, 2000, 10), [100, 101]) * MS)
    lossy = Stream(
        "/wrench", "wrench", np.delete(wrench.stamps, lost), np.delete(wrench.values, lost, axis=0)
    )
    clocked = put_on_clock(lossy, joints, source="log")
    assert clocked.report.max_gap == allowed
    assert clocked.report.wrench.n_gaps == 1 and clocked.report.joints.n_gaps == 0
    bridged = put_on_clock(
        Stream(
            "/wrench",
            "wrench",
            np.delete(wrench.stamps, lost[1:]),
            np.delete(wrench.values, lost[1:], axis=0),
        ),
        joints,
        source="log",
    )
    assert bridged.report.n_left_out == 0 and bridged.report.wrench.n_gaps == 0
    # three joint messages lost (30 ms of joints at 100 Hz): a gap too
    silent = _ramp_joints(EPOCH_NS + np.delete(np.arange(0, 2000, 10), [100, 101, 102]) * MS)
    assert put_on_clock(wrench, silent, source="log").report.joints.n_gaps == 1


def test_streams_that_do_not_overlap_or_repeat_a_stamp_are_refused() -> None:
    wrench = _wrench(10)
    later = _ramp_joints(EPOCH_NS + np.arange(10, 20, dtype=np.int64) * MS)
    with pytest.raises(ImporterError, match=r"^log: '/wrench' \(.*\) do not overlap in time$"):
        put_on_clock(wrench, later, source="log")
    repeated = _ramp_joints(EPOCH_NS + np.array([0, MS, MS, 2 * MS], dtype=np.int64))
    with pytest.raises(ImporterError, match=r"'/joints': messages 1 and 2 .* same stamp"):
        put_on_clock(wrench, repeated, source="log")


def _jittered(wrench: Stream, stamps: np.ndarray) -> Stream:
    return Stream(name=wrench.name, kind=wrench.kind, stamps=stamps, values=wrench.values)


@pytest.mark.parametrize("n", [3000, 2001, 2003])
@pytest.mark.parametrize(
    "how",
    ["stamps jittered by up to half a period", "a recorder's latency of 0 to 2 periods", "bursts"],
)
def test_every_message_keeps_its_own_sample_whatever_its_stamp_s_jitter(how: str, n: int) -> None:
    # samples at 1 kHz, none dropped, stamped three ways a lab meets: a logger's jitter of up
    # to +-0.5 ms; a recorder's arrival time, 0 to 2 ms late and in order; arrivals four at a
    # time, 10 us apart, every 4 ms (a step rounded to its nearest whole number of median steps
    # reads them as 1127 Hz, 1320 Hz and 100 kHz). The sensor's 1 kHz, and each message its
    # own sample, whatever the stream's length against the bursts
    rng = np.random.default_rng(5)
    wrench = _wrench(n)
    k = np.arange(n, dtype=np.int64)
    if how.startswith("stamps"):
        stamps = wrench.stamps + rng.integers(-MS // 2 + 1, MS // 2, size=n)
    elif how.startswith("a recorder"):
        arrival = wrench.stamps + rng.integers(0, 2 * MS, size=n)
        stamps = np.maximum.accumulate(arrival) + k  # in order, one nanosecond apart at least
    else:
        stamps = EPOCH_NS + (k // 4 * 4 + 3) * MS + (k % 4) * 10_000
    # the joints cover the whole stream, 5 ms late included
    joints = _ramp_joints(EPOCH_NS + np.arange(-10, n + 20, 10, dtype=np.int64) * MS)
    clocked = put_on_clock(_jittered(wrench, stamps), joints, source="log")
    report = clocked.report
    assert report.period == pytest.approx(0.001, rel=2e-4)  # the clock tolerance is 1e-3
    assert report.wrench.n_missing == report.wrench.n_gaps == 0
    assert report.n_samples == n and report.n_interpolated == report.n_left_out == 0
    np.testing.assert_array_equal(clocked.wrench, wrench.values)


def test_dropped_messages_are_counted_under_jitter_and_bridged_or_left_out() -> None:
    # stamps jittered by up to +-0.4 ms; two messages dropped (bridged: the estimators take up
    # to twenty in a row) and later thirty (a gap, left out)
    rng = np.random.default_rng(6)
    n = 2000
    wrench = _wrench(n)
    kept = np.setdiff1d(np.arange(n), [700, 701, *range(1300, 1330)])
    stamps = wrench.stamps + rng.integers(-400_000, 400_001, size=n)
    lossy = Stream("/wrench", "wrench", stamps[kept], wrench.values[kept])
    joints = _ramp_joints(EPOCH_NS + np.arange(-10, n + 10, 10, dtype=np.int64) * MS)
    clocked = put_on_clock(lossy, joints, source="log")
    report = clocked.report
    assert report.wrench.n_missing == 32 and report.wrench.n_gaps == 1
    assert report.n_interpolated == 2 and report.n_left_out == 30
    slots = np.rint(clocked.t / report.period).astype(int)
    assert set(range(n)) - set(slots) == set(range(1300, 1330))
    own = np.isin(slots, kept)
    np.testing.assert_array_equal(clocked.wrench[own], wrench.values[slots[own]])


@pytest.mark.parametrize("seed", range(3))
def test_scattered_drops_under_a_fifth_of_a_period_of_jitter_are_each_counted(seed: int) -> None:
    # a 1 kHz sensor, its stamps jittered by +-0.2 ms, 2 % of its messages lost at random
    # (about 60, rarely two in a row): each step's own rounding counts them, and the rate is
    # read as 1 kHz, where the running medians, which need most messages without a drop, read
    # 984 to 996 Hz
    rng = np.random.default_rng(seed)
    n = 3000
    wrench = _wrench(n)
    kept = np.flatnonzero(rng.random(n) >= 0.02)
    kept = np.union1d(kept, [0, n - 1])
    stamps = wrench.stamps + rng.integers(-200_000, 200_001, size=n)
    lossy = Stream("/wrench", "wrench", stamps[kept], wrench.values[kept])
    joints = _ramp_joints(EPOCH_NS + np.arange(-10, n + 10, 10, dtype=np.int64) * MS)
    report = put_on_clock(lossy, joints, source="log").report
    assert report.period == pytest.approx(1e-3, rel=1e-4)
    assert report.wrench.n_missing == n - kept.size


def test_drops_are_counted_step_by_step_on_a_clock_whose_rate_drifts() -> None:
    # a sensor whose rate drifts by 2e-4 over 20 s (a host clock slewed by NTP), a third of
    # its messages lost, stamps jittered by 0.05 ms: the stamps bend away from one line by
    # more than half a period over the stream, but never step; each step's rounding counts
    # every drop
    rng = np.random.default_rng(1)
    n = 20_000
    k = np.arange(n)
    kept = np.union1d(np.flatnonzero(rng.random(n) > 0.3), [0, n - 1])
    instants = MS * k * (1.0 + 1e-4 * k / n)
    stamps = EPOCH_NS + np.rint(instants[kept] + rng.uniform(-50_000, 50_000, kept.size))
    wrench = _wrench(n)
    lossy = Stream("/wrench", "wrench", stamps.astype(np.int64), wrench.values[kept])
    joints = _ramp_joints(EPOCH_NS + np.arange(-10, n + 20, 10, dtype=np.int64) * MS)
    report = put_on_clock(lossy, joints, source="log").report
    assert report.wrench.n_missing == n - kept.size


def test_a_recorder_that_stalls_by_more_than_half_a_period_counts_no_drop() -> None:
    # stamps on their grid but for a stall: one message 0.6 ms late, the next two catching up.
    # Each step lies within 0.45 of a whole period, but rounding would count a drop at the
    # stall and none at the catching up; the stamps' line says so, and no drop is counted
    n = 2000
    wrench = _wrench(n)
    stamps = wrench.stamps.copy()
    stamps[1000:1003] += np.array([600_000, 400_000, 200_000])
    stalled = Stream("/wrench", "wrench", stamps, wrench.values)
    joints = _ramp_joints(EPOCH_NS + np.arange(-10, n + 10, 10, dtype=np.int64) * MS)
    report = put_on_clock(stalled, joints, source="log").report
    assert report.wrench.n_missing == 0
    assert report.period == pytest.approx(1e-3, rel=1e-4)


def test_the_report_says_what_the_clock_leaves_out_or_makes_up() -> None:
    wrench = _wrench(1000)
    joints = _ramp_joints(EPOCH_NS + np.arange(300, 1000, 10, dtype=np.int64) * MS)
    lines = put_on_clock(wrench, joints, source="log").report.lines()
    assert lines[-1].startswith("the wrench's first 0.3 s and last 0.009 s left out:")
    faster = put_on_clock(wrench, _ramp_joints(wrench.stamps), source="log", period=1 / 3000)
    assert faster.report.lines()[-1] == (
        "the clock's 3000 Hz is above the wrench's own 1000 Hz: the samples between its "
        "messages are interpolated"
    )


@pytest.mark.parametrize("dropped", [[700, 710], [700, 701, 710, 711], [5, 12], [1990, 1995]])
def test_drops_close_together_keep_every_message_on_its_sample(dropped: list[int]) -> None:
    # stamps on their grid: each drop where its step is, however close the next, and two
    # holes that may each be bridged not made into one gap
    n = 2000
    wrench = _wrench(n)
    kept = np.setdiff1d(np.arange(n), dropped)
    lossy = Stream("/wrench", "wrench", wrench.stamps[kept], wrench.values[kept])
    joints = _ramp_joints(EPOCH_NS + np.arange(0, n + 10, 10, dtype=np.int64) * MS)
    clocked = put_on_clock(lossy, joints, source="log")
    assert clocked.report.wrench.n_missing == len(dropped)
    assert clocked.report.n_left_out == 0 and clocked.report.n_interpolated == len(dropped)
    np.testing.assert_array_equal(clocked.wrench[kept], wrench.values[kept])


@pytest.mark.parametrize("seed", range(5))
def test_a_drop_under_a_recorder_s_latency_is_counted_whole(seed: int) -> None:
    # stamps late by 0 to 2 periods (in order) and 3 samples lost: all three counted, every
    # message on its own sample but near the hole, where the late stamps blur which step it is
    rng = np.random.default_rng(seed)
    n = 2000
    wrench = _wrench(n)
    k = np.arange(n, dtype=np.int64)
    stamps = np.maximum.accumulate(wrench.stamps + rng.integers(0, 2 * MS, size=n)) + k
    kept = np.setdiff1d(np.arange(n), [900, 901, 902])
    lossy = Stream("/wrench", "wrench", stamps[kept], wrench.values[kept])
    joints = _ramp_joints(EPOCH_NS + np.arange(-10, n + 20, 10, dtype=np.int64) * MS)
    clocked = put_on_clock(lossy, joints, source="log")
    assert clocked.report.wrench.n_missing == 3
    far = np.abs(kept - 901) > 5
    np.testing.assert_array_equal(clocked.wrench[kept[far]], wrench.values[kept[far]])


def test_a_clock_set_back_while_recording_is_refused() -> None:
    # the stamps' clock set back by 20 ms half-way (an NTP step): sorted, two stretches of
    # samples interleave, and a line through them would put the sensor at 1.01 kHz
    rng = np.random.default_rng(2)
    n = 3000
    wrench = _wrench(n)
    stamps = wrench.stamps + rng.integers(-200_000, 200_001, size=n)
    stamps[1500:] -= 20 * MS
    order = np.argsort(stamps, kind="stable")
    stepped = Stream("/wrench", "wrench", stamps[order], wrench.values[order])
    joints = _ramp_joints(EPOCH_NS + np.arange(-10, n + 10, 10, dtype=np.int64) * MS)
    with pytest.raises(
        ImporterError, match=r"^log: '/wrench': its stamps fall back by about 0\.0(19|20)\d* s"
    ):
        put_on_clock(stepped, joints, source="log")


def test_joints_sent_on_change_are_not_gaps_while_they_stand_still() -> None:
    # a publisher that sends the angles only when they change: silent for 0.5 s while the head
    # stands, then at 1 kHz while it moves; the silence is no gap (the straight line across it
    # is the path), a silence across which the angles moved is
    n = 3000
    wrench = _wrench(n)
    t = np.arange(n) * 0.001
    theta1 = np.where(t < 1.0, 0.0, 0.3 * (t - 1.0))
    sent = (t <= 0.5) | (t >= 1.0)
    sent[2000:2030] = False  # thirty lost while moving
    stamps = wrench.stamps[sent]
    joints = Stream("/joints", "joints", stamps, np.column_stack([theta1[sent], 0.0 * t[sent]]))
    clocked = put_on_clock(wrench, joints, source="log")
    assert clocked.report.n_left_out == 30 and clocked.report.joints.n_gaps == 1
    joints_report = clocked.report.joints
    assert (joints_report.n_missing, joints_report.n_still) == (529, 499)
    assert "529 missing (499 of them while the angles stood still: no gap, the angles held)" in (
        joints_report.line()
    )
    np.testing.assert_allclose(
        clocked.joints[:, 0], np.delete(theta1, range(2000, 2030)), atol=1e-12
    )


@pytest.mark.parametrize("lost", ["1 % at random", "5 % at random", "every 50th"])
def test_many_drops_on_stamps_without_jitter_are_each_counted(lost: str) -> None:
    # so many drops that nearly every 64 messages hold one: stamps on their grid count each
    # step's own drops, at the sensor's own rate
    rng = np.random.default_rng(8)
    n = 3000
    wrench = _wrench(n)
    if lost == "every 50th":
        dropped = np.arange(49, n - 1, 50)
    else:
        share = 0.01 if lost.startswith("1") else 0.05
        dropped = rng.choice(np.arange(1, n - 1), int(share * n), replace=False)
    kept = np.setdiff1d(np.arange(n), dropped)
    lossy = Stream("/wrench", "wrench", wrench.stamps[kept], wrench.values[kept])
    joints = _ramp_joints(EPOCH_NS + np.arange(0, n + 10, 10, dtype=np.int64) * MS)
    clocked = put_on_clock(lossy, joints, source="log")
    assert clocked.report.period == 0.001
    assert clocked.report.wrench.n_missing == dropped.size
    slots = np.rint(clocked.t / 0.001).astype(int)
    own = np.isin(slots, kept)
    np.testing.assert_array_equal(clocked.wrench[own], wrench.values[slots[own]])


def test_stamps_in_floats_or_microseconds_are_refused_naming_the_unit() -> None:
    # A lab's log stamped in float seconds, or in integer microseconds passed as nanoseconds:
    # one line naming the stream and the unit, not a clock of 1e12 or 1e6 Hz written out.
    wrench = _wrench(200)
    joints = _ramp_joints(wrench.stamps)
    seconds = Stream("/wrench", "wrench", wrench.stamps / 1e9, wrench.values)
    with pytest.raises(ImporterError, match=r"^log: '/wrench': stamps must be whole nanoseconds"):
        put_on_clock(seconds, joints, source="log")
    unsigned = Stream("/wrench", "wrench", wrench.stamps.astype(np.uint64), wrench.values)
    with pytest.raises(ImporterError, match=r"got uint64 .*astype\(np.int64\)"):
        put_on_clock(unsigned, joints, source="log")
    backwards = wrench.stamps.copy()
    backwards[[50, 51]] = backwards[[51, 50]]
    with pytest.raises(ImporterError, match=r"messages 50 and 51 are not in time order"):
        put_on_clock(Stream("/wrench", "wrench", backwards, wrench.values), joints, source="log")
    micro = _wrench(200, period_ns=1000, start_ns=EPOCH_NS // 1000)
    with pytest.raises(ImporterError, match=r"sensor reads \(100000 Hz\): stamps in"):
        put_on_clock(micro, _ramp_joints(micro.stamps), source="log")


def test_streams_passed_the_other_way_round_are_named() -> None:
    wrench = _wrench(200)
    joints = _ramp_joints(wrench.stamps)
    with pytest.raises(ImporterError, match=r"other way round") as swapped:
        put_on_clock(joints, wrench, source="log")
    assert "'/joints': values of shape (200, 2) for 200 stamps" in str(swapped.value)
    three = Stream("/wrench", "wrench", wrench.stamps, wrench.values[:, :3])
    with pytest.raises(ImporterError, match=r"the wrench stream has 6 per stamp"):
        put_on_clock(three, joints, source="log")
