"""The recording of a manoeuvre's mirror image: a sweep towards -Y^m from one towards +Y^m.

Reflect the whole manoeuvre in the X-Z plane of its absolute frame, S = diag(1, -1, 1). Gravity
lies along -Z^a and is unchanged, so the reflected motion obeys the same physics (the link is
round, the head level): it is the manoeuvre a device sweeping the other way performs. The head
at (theta1, theta2) maps to (-theta1, theta2): the motor frame of the recording format turns into
X^m' = S X^m, Y^m' = -S Y^m, Z^m' = S Z^m (Y^m keeps its handedness: X^m' x Y^m' = Z^m'). A
force is a vector, F' = S F; a torque is a pseudovector, Gamma' = -S Gamma (det S = -1). On the
motor axes that is

    fx' = fx,  fy' = -fy,  fz' = fz,  tx' = -tx,  ty' = ty,  tz' = -tz,

and the joint-1 quantities change sign (theta1, theta1_ref, the voltage u1). The ground truth
follows: absolute-frame points have y -> -y, the obstacle's axis or normal is reflected; the
contact abscissa, times and the deflection ratio are unchanged. ``simulation`` keeps the
scenario that was run and says that the recording is its mirror image (``"mirror": "y"``; the
mirror of a mirror image is the original recording).
"""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np

from sensing_antenna.recording import CONTACT_POINT_COLUMNS, Recording

__all__ = ["mirror_recording"]

#: Extra columns whose sign flips under the reflection (joint 1's angle and command, the
#: contact track's y).
_ODD_COLUMNS = ("theta1_ref", "u1", CONTACT_POINT_COLUMNS[1])


def _reflect(values: object) -> list[float] | None:
    if values is None:
        return None
    x, y, z = (float(v) for v in values)  # type: ignore[attr-defined]
    return [x, -y, z]


def mirror_recording(recording: Recording) -> Recording:
    """The recording of ``recording``'s manoeuvre reflected in its absolute X-Z plane (module
    docstring): same times, theta1 -> -theta1, fy, tx, tz -> their negatives."""
    theta = recording.theta.copy()
    theta[:, 0] = -theta[:, 0]
    force = recording.force * np.array([1.0, -1.0, 1.0])
    torque = recording.torque * np.array([-1.0, 1.0, -1.0])
    extra = {
        name: (-column if name in _ODD_COLUMNS else column.copy())
        for name, column in recording.extra.items()
    }
    metadata = dict(recording.metadata)
    if "true_contact_point" in metadata:
        metadata["true_contact_point"] = json.dumps(
            _reflect(json.loads(metadata["true_contact_point"]))
        )
    if "true_obstacle" in metadata:
        obstacle = json.loads(metadata["true_obstacle"])
        obstacle["point"] = _reflect(obstacle["point"])
        obstacle["direction"] = _reflect(obstacle["direction"])
        if "axes" in obstacle:  # a solid's own axes, each reflected (its shape is symmetric)
            rows = obstacle["axes"]
            axes = rows[0:3], rows[3:6], rows[6:9]
            obstacle["axes"] = [v for axis in axes for v in _reflect(axis) or ()]
        metadata["true_obstacle"] = json.dumps(obstacle)
    if "simulation" in metadata:
        simulation = json.loads(metadata["simulation"])
        if simulation.pop("mirror", None) is None:
            simulation["mirror"] = "y"
        metadata["simulation"] = json.dumps(simulation, sort_keys=True)
    return replace(
        recording, theta=theta, force=force, torque=torque, metadata=metadata, extra=extra
    )
