"""``antenna listen`` at 1 kHz for a sustained time: samples dropped and latency, per method.

A sender process replays two simulated recordings of the paper antenna (the azimuthal case at
x_c = 0.6 m and the vertical case at x_c = 0.7 m, 3 s each) one after the other over UDP on
localhost, at their own pace (1 kHz, one datagram a sample), for ``--duration`` seconds; this
process listens (the reader of :func:`sensing_antenna.live.inputs.listen_udp`, a listener and
its worker thread per recording), as ``antenna listen --udp`` does, warmed up as it is by
default (:func:`sensing_antenna.live.warm_up.warm_up`: one simulated manoeuvre through the
method, then the heap frozen), as a lab would start its listener before its first manoeuvre.

Reported per method: recordings and samples received, samples dropped (sent but not received),
whether every recording's estimate equals the offline ``estimate`` of the same recording, the
latency of the events (wall time from the receipt of the sample an event is at to its
emission: p50, p99, max over all events but the ends, over the estimates alone, and over the
instants: contact, push, contact lost) and the worker's lag
(for each block it took, from the receipt of its first sample to the end of its processing).
The target: no sample dropped, p99 latency under 20 ms. Each method's row also holds when it
ran, for how long and the load average of the machine before and after (the listener shares the
cores with the sender and whatever else runs). The results file keeps the rows of the methods
not run this time.

Usage::

    python benchmarks/bench_listen.py                      # 10 minutes per method
    python benchmarks/bench_listen.py --duration 60 --methods fast
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")  # one BLAS thread, set before numpy loads

import argparse  # noqa: E402
import datetime  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import platform  # noqa: E402
import socket  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

import numpy as np  # noqa: E402

from sensing_antenna.antenna import paper_antenna  # noqa: E402
from sensing_antenna.estimation import estimate  # noqa: E402
from sensing_antenna.live.events import (  # noqa: E402
    ContactEvent,
    ContactLostEvent,
    EndEvent,
    EstimateEvent,
    Event,
    PushEvent,
)
from sensing_antenna.live.inputs import listen_udp  # noqa: E402
from sensing_antenna.live.listener import Listener  # noqa: E402
from sensing_antenna.live.warm_up import warm_up  # noqa: E402
from sensing_antenna.live.wire import StreamHeader  # noqa: E402
from sensing_antenna.recording import read_recording, write_recording  # noqa: E402
from sensing_antenna.simulator import Scenario, simulate  # noqa: E402

RESULTS = Path(__file__).resolve().parent / "results" / "listen.json"
METHODS = ("paper", "ratio", "two-frequency", "fast")
#: The target: p99 of the sample-to-event latency (s).
TARGET_P99_S = 0.020
CASES = (("azimuthal", 0.6, 1), ("vertical", 0.7, 2))

_SENDER = """
import socket, sys
from sensing_antenna.live.replay import replay_datagrams
from sensing_antenna.recording import read_recording
port, count = int(sys.argv[1]), int(sys.argv[2])
recordings = [read_recording(p) for p in sys.argv[3:]]
with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
    for k in range(count):
        replay_datagrams(recordings[k % len(recordings)], sock, ("127.0.0.1", port), 1.0,
                         stream=f"r{k}")
"""


def _percentiles(values: list[float]) -> dict[str, float | None]:
    if not values:
        return {"p50": None, "p99": None, "max": None, "count": 0}
    array = np.asarray(values)
    return {
        "p50": float(np.percentile(array, 50)),
        "p99": float(np.percentile(array, 99)),
        "max": float(array.max()),
        "count": int(array.size),
    }


def run_method(method: str, files: list[Path], duration: float) -> dict[str, Any]:
    """One sustained run of ``method`` (module docstring)."""
    # the estimators' model: the simulated device's own T as a calibration gives it (0.1 %)
    antenna = paper_antenna().self_calibrated()
    recordings = [read_recording(path) for path in files]
    offline = [estimate(r, antenna, method).to_dict() for r in recordings]
    warm_up(antenna, method)  # as antenna listen does before listening
    load_before = os.getloadavg()
    started = datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds")
    per_recording = recordings[0].duration + recordings[0].sample_period
    count = max(1, math.ceil(duration / per_recording))
    events: list[Event] = []
    listeners: list[Listener] = []

    def make(header: StreamHeader, number: int) -> Listener:
        listener = Listener(header, antenna, events.append, method, number=number)
        listeners.append(listener)
        return listener

    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 22)
        sock.bind(("127.0.0.1", 0))
        port = sock.getsockname()[1]
        sender = subprocess.Popen(
            [sys.executable, "-c", _SENDER, str(port), str(count), *map(str, files)]
        )
        try:
            ended = listen_udp(sock, make, events.append, count)
        finally:
            sender.wait(timeout=60)
    ends = [e for e in events if isinstance(e, EndEvent)]
    estimates = [e for e in events if isinstance(e, EstimateEvent)]
    sent = sum(recordings[k % len(recordings)].n_samples for k in range(count))
    received = sum(e.samples for e in ends)
    identical = 0
    for event in estimates:
        mine = event.estimate.to_dict()
        reference = offline[(event.recording - 1) % len(recordings)]
        keys = [k for k in reference if k != "diagnostics"]
        identical += all(mine[k] == reference[k] for k in keys)
    latencies = [e.latency for e in events if not isinstance(e, EndEvent)]
    return {
        "method": method,
        "date": started,
        "duration_s": duration,
        "load_average_before": [round(x, 2) for x in load_before],
        "load_average_after": [round(x, 2) for x in os.getloadavg()],
        "recordings_sent": count,
        "recordings_ended": ended,
        "samples_sent": sent,
        "samples_received": received,
        "dropped": sent - received,
        "estimates": len(estimates),
        "estimates_identical_to_offline": identical,
        "event_latency_s": _percentiles(latencies),
        "estimate_latency_s": _percentiles([e.latency for e in estimates]),
        "instant_latency_s": _percentiles(
            [
                e.latency
                for e in events
                if isinstance(e, (ContactEvent, PushEvent, ContactLostEvent))
            ]
        ),
        "worker_lag_s": _percentiles([lag for listener in listeners for lag in listener.lags]),
        "skipped": [e.to_dict() for e in events if e.to_dict()["event"] == "skipped"][:5],
    }


def _ms(value: float | None) -> str:
    return "-" if value is None else f"{1000 * value:.1f}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--duration", type=float, default=600.0, help="seconds per method")
    parser.add_argument("--methods", default=",".join(METHODS))
    parser.add_argument("--out", type=Path, default=RESULTS)
    args = parser.parse_args()
    antenna = paper_antenna()
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        files = []
        for case, x_c, seed in CASES:
            path = Path(folder) / f"{case}.csv"
            scenario = Scenario(case=case, contact_point=x_c, seed=seed)
            write_recording(simulate(antenna, scenario).without_ground_truth(), path)
            files.append(path)
        for method in args.methods.split(","):
            rows.append(run_method(method, files, args.duration))
            row = rows[-1]
            print(
                f"{method:14s} load {row['load_average_before'][0]:.2f}->"
                f"{row['load_average_after'][0]:.2f} recordings {row['recordings_ended']:4d}"
                " samples"
                f" {row['samples_received']:7d} dropped {row['dropped']:4d} identical"
                f" {row['estimates_identical_to_offline']}/{row['estimates']}"
                "  latency ms p50/p99/max "
                + "/".join(_ms(row["event_latency_s"][k]) for k in ("p50", "p99", "max"))
                + "  estimate "
                + "/".join(_ms(row["estimate_latency_s"][k]) for k in ("p50", "p99", "max"))
                + "  instants "
                + "/".join(_ms(row["instant_latency_s"][k]) for k in ("p50", "p99", "max"))
                + "  lag "
                + "/".join(_ms(row["worker_lag_s"][k]) for k in ("p50", "p99", "max")),
                flush=True,
            )
    run = {row["method"] for row in rows}
    kept = []
    if args.out.exists():
        earlier = json.loads(args.out.read_text())
        for row in earlier["methods"]:
            if row["method"] not in run:
                # rows of files written before the rows held their own date and duration
                row.setdefault("date", earlier.get("date"))
                row.setdefault("duration_s", earlier.get("duration_s"))
                kept.append(row)
    data = {
        "machine": {"python": platform.python_version(), "cpus": os.cpu_count()},
        "rate_hz": 1000,
        "target_p99_s": TARGET_P99_S,
        "methods": sorted(
            kept + rows,
            key=lambda row: METHODS.index(row["method"]) if row["method"] in METHODS else 99,
        ),
    }
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(data, indent=2) + "\n")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
