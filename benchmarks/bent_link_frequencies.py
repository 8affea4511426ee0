"""In-plane fundamental of the pushed link, with the contact sliding along the obstacle or held.

An independent check of why the push plane of a bent link rings above the straight link's
contact frequency (docs/estimation.md, "The two bending planes"): a planar frame of 196
Euler-Bernoulli elements with axial stiffness E A (consistent mass, geometric stiffness of the
axial force the reaction puts along the bent link), laid along the linear shape of the paper's
link pushed at x_c to a deflection y_c / x_c = d (the slope integrated along the arc, so the
arc length is the link's). Clamped at O; at the contact the displacement along the reaction is
held (the obstacle), and either

- ``slide``: the contact may slide along the obstacle's surface (pinned with sliding, the
  straight link's model), or
- ``stick``: friction holds it there too (pinned without sliding).

Prints the relative shift of the in-plane fundamental from the straight link's omega_1 at x_c
(``sensing_antenna.beam.natural_frequencies``), with and without the axial force.

Usage::

    python benchmarks/bent_link_frequencies.py
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

from sensing_antenna import paper_antenna
from sensing_antenna.beam import natural_frequencies

ELEMENTS = 196
DEFLECTIONS = (0.0, 0.03, 0.10, 0.24, 0.31)
CONTACTS = (0.3, 0.5, 0.7, 0.9)


def in_plane_fundamental(x_c: float, d: float, stick: bool, axial_force: bool = True) -> float:
    """Lowest in-plane natural frequency (rad/s) of the link pushed at x_c to y_c / x_c = d."""
    link = paper_antenna().link
    length, rho = link.length, link.linear_density
    area = np.pi * link.radius**2
    ei = 1.0 / link.bending_compliance
    ea = link.youngs_modulus * area
    s = np.linspace(0.0, length, ELEMENTS + 1)
    k_c = int(np.argmin(np.abs(s - x_c)))
    x_c = float(s[k_c])
    push = 3.0 * ei * d / x_c**2
    slope = np.where(s <= x_c, push * s * (2 * x_c - s) / (2 * ei), push * x_c**2 / (2 * ei))
    mid = 0.5 * (slope[1:] + slope[:-1])
    x = np.concatenate([[0.0], np.cumsum(np.diff(s) * np.cos(mid))])
    y = -np.concatenate([[0.0], np.cumsum(np.diff(s) * np.sin(mid))])
    n_dof = 3 * (ELEMENTS + 1)
    stiffness = np.zeros((n_dof, n_dof))
    mass = np.zeros((n_dof, n_dof))
    bend = [1, 2, 4, 5]
    for e in range(ELEMENTS):
        dx, dy = x[e + 1] - x[e], y[e + 1] - y[e]
        h = float(np.hypot(dx, dy))
        c, sn = dx / h, dy / h
        # the reaction (0, -push) acts on the part beyond the contact: its share along the axis
        tension = -push * sn if (axial_force and s[e] < x_c) else 0.0
        k = np.zeros((6, 6))
        k[np.ix_([0, 3], [0, 3])] = ea / h * np.array([[1.0, -1.0], [-1.0, 1.0]])
        k[np.ix_(bend, bend)] = ei / h**3 * np.array(
            [
                [12, 6 * h, -12, 6 * h],
                [6 * h, 4 * h**2, -6 * h, 2 * h**2],
                [-12, -6 * h, 12, -6 * h],
                [6 * h, 2 * h**2, -6 * h, 4 * h**2],
            ]
        ) + tension / (30 * h) * np.array(
            [
                [36, 3 * h, -36, 3 * h],
                [3 * h, 4 * h**2, -3 * h, -(h**2)],
                [-36, -3 * h, 36, -3 * h],
                [3 * h, -(h**2), -3 * h, 4 * h**2],
            ]
        )
        m = np.zeros((6, 6))
        m[np.ix_([0, 3], [0, 3])] = rho * h / 6 * np.array([[2.0, 1.0], [1.0, 2.0]])
        m[np.ix_(bend, bend)] = (
            rho
            * h
            / 420
            * np.array(
                [
                    [156, 22 * h, 54, -13 * h],
                    [22 * h, 4 * h**2, 13 * h, -3 * h**2],
                    [54, 13 * h, 156, -22 * h],
                    [-13 * h, -3 * h**2, -22 * h, 4 * h**2],
                ]
            )
        )
        rotation = np.array([[c, sn, 0.0], [-sn, c, 0.0], [0.0, 0.0, 1.0]])
        t = np.zeros((6, 6))
        t[:3, :3] = rotation
        t[3:, 3:] = rotation
        dofs = np.arange(3 * e, 3 * e + 6)
        stiffness[np.ix_(dofs, dofs)] += t.T @ k @ t
        mass[np.ix_(dofs, dofs)] += t.T @ m @ t
    held = [0, 1, 2, 3 * k_c + 1] + ([3 * k_c] if stick else [])
    free = np.setdiff1d(np.arange(n_dof), held)
    values = scipy.linalg.eigh(
        stiffness[np.ix_(free, free)],
        mass[np.ix_(free, free)],
        eigvals_only=True,
        subset_by_index=[0, 0],
    )
    return float(np.sqrt(values[0]))


def main() -> None:
    link = paper_antenna().link
    for x_c in CONTACTS:
        beam = float(np.ravel(natural_frequencies(link, np.array([x_c]), 1))[0])
        print(f"x_c {x_c:.1f} m, straight link omega_1 {beam:.2f} rad/s")
        for d in DEFLECTIONS:
            slide = in_plane_fundamental(x_c, d, stick=False)
            stick = in_plane_fundamental(x_c, d, stick=True)
            bare = in_plane_fundamental(x_c, d, stick=True, axial_force=False)
            print(
                f"  d {d:.2f}: sliding {100 * (slide / beam - 1):+6.1f} %,"
                f" held {100 * (stick / beam - 1):+6.1f} %"
                f" (held, no axial force {100 * (bare / beam - 1):+6.1f} %)"
            )


if __name__ == "__main__":
    main()
