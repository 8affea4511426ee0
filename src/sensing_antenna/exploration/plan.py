"""Which sweep next: a fixed grid, or the sweep expected to reduce the surface's uncertainty most.

The grid (:func:`grid_sweeps`) runs, from each base, azimuthal sweeps across the base's azimuth
range (``Scene.region_of``) at evenly spaced elevations, each elevation both ways (towards +Y^m
and -Y^m: a sweeping line touches a convex object on the side it comes from, so the two see
opposite sides), and vertical sweeps across its elevation range at evenly spaced azimuths,
up at the even ones and down at the odd (an upward sweep touches the outline's underside, a
downward one its top), in an order that spreads them out first (:func:`spread_order`), so
that a budget cut short still covers the region.

The next-best strategy (:class:`NextBestPlanner`) chooses among the candidates of a grid
:data:`CANDIDATE_DENSITY` times finer. Until the surface can be fitted (fewer than
``MIN_SURFACE_POINTS`` usable contacts) it takes the coarse grid's sweeps in their spread-out
order. Then, for every candidate not yet run, it follows the candidate's link through the
fitted implicit surface f (negative inside) in steps of :data:`PREDICTION_STEP`: the predicted
touch is the first link sample where f < 0, or, when the candidate is predicted to miss, the
sample where f is smallest (where the sweep passes closest to the estimated surface). The
candidate's score is the surface's predictive standard deviation sigma there, weighted by the
chance that the sweep touches at all, P(f < 0) = Phi(-f / sigma) at that sample under the
surface's Gaussian prediction: the sweep whose expected touch lands where the surface is least
known, which is what a contact there reduces most, unless it is likely to miss. Free space
counts against a prediction: a sweep that came back free swept its link through space the
object does not occupy, so a candidate whose predicted touch lies within about
:data:`FREE_RADIUS` of a free sweep's link is unlikely to touch there, and its score is
multiplied by 1 - exp(-d^2 / (2 FREE_RADIUS^2)), d the distance to the nearest free link
sample. Candidates predicted to miss by more than :data:`MISS_MARGIN` of f count only if nothing
else is left, and each score is divided by one plus the number of earlier sweeps within
:data:`NEIGHBOUR_ANGLE` of it (its held angle) from the same base, of the same case and
direction, which keeps a sweep that came back free from being retried next to itself.

When recognition abstains between two leading shape classes, the planner also aims at telling
them apart by what each predicts the candidate will find (:meth:`NextBestPlanner.separation`):
each fitted shape is followed through the candidate's sweep as the surface is, and where one
predicts the touch, the other's surface is s from the link: 0 when they agree, the gap the
link has still to close (or has passed) when one is touched later, the other's distance there
when it is not touched at all, the larger of the two ways round, at most :data:`MISS_MARGIN`
(a gap of a few cm is decisive already); 0 when neither is touched, when the link starts
inside one, or when a distance is not finite. The score is then
sqrt(score^2 + (s / (1 + crowd))^2), and a candidate the leaders disagree about is never
relegated as a predicted miss: a contact, or free space, where the leaders differ separates
them; one where they agree does not.

The leading fit (the named object's, or the better of the two) is a second model of the same
surface, held by its few parameters: where its points do not reach (a cone's apex, a cylinder's
end) it extrapolates, and the sizes it reads there are as good as that extrapolation. So each
candidate is also followed through that fit, as through the surface: the standard deviation u of
the fit's signed distance at its predicted touch (or closest pass), from the fit's parameter
covariance (``ClassFit.distance_std``, at most :data:`MISS_MARGIN`), and the chance Phi(-d / u)
that the sweep touches the fit at all, d the fit's smallest distance to the link over the sweep,
give the fit's term Phi(-d / u) u, which a contact there would reduce; a free sweep near the
fit's touch discounts it as it discounts the surface's (the fit may not have seen that sweep:
recognition runs every few manoeuvres). With both, the score is
sqrt(score^2 + (separation / (1 + crowd))^2 + (Phi(-d / u) u / (1 + crowd))^2), and a candidate
whose touch the fit gives a fair chance (d at most 2 u and :data:`MISS_MARGIN`) is not relegated
as a predicted miss.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import cKDTree

from sensing_antenna.mapping.primitives import PRIMITIVES
from sensing_antenna.mapping.recognition import ClassFit
from sensing_antenna.mapping.surface import ImplicitSurface
from sensing_antenna.scene.file import Scene
from sensing_antenna.scene.sweep import LinkShape, Sweep

__all__ = [
    "CANDIDATE_DENSITY",
    "FREE_RADIUS",
    "MISS_MARGIN",
    "NEIGHBOUR_ANGLE",
    "PREDICTION_STEP",
    "STRATEGIES",
    "NextBestPlanner",
    "candidate_sweeps",
    "grid_sweeps",
    "spread_order",
]

FloatArray = NDArray[np.float64]

#: The strategies ``antenna explore --strategy`` offers.
STRATEGIES = ("grid", "next-best")

#: The next-best candidates are a grid this many times finer than the scene's.
CANDIDATE_DENSITY = 3

#: Angle step (rad) at which a candidate's link is followed through the fitted surface: 1 cm
#: at 1 m, about the surface's finest length scale.
PREDICTION_STEP = 0.01

#: A candidate whose link stays this far outside the fitted surface (m of f) is predicted to
#: miss it: 2 cm, several times the points' standard deviation.
MISS_MARGIN = 0.02

#: Sweeps whose held angles are closer than this (rad) count as neighbours: half the coarse
#: grid's spacing for the built-in scenes.
NEIGHBOUR_ANGLE = 0.05

#: How near a free sweep's link a predicted touch is contradicted (m): the free sweeps are
#: followed every :data:`PREDICTION_STEP` (6 mm apart at 0.6 m) with samples 1 cm apart.
FREE_RADIUS = 0.01

#: Samples along the link used for the predictions (every 1 cm for a 1 m link).
_PREDICTION_SAMPLES = 100


def _unswept(free_cloud: cKDTree | None, point: FloatArray) -> float:
    """1 - exp(-d^2 / (2 FREE_RADIUS^2)), d the distance (m) from ``point`` to the nearest
    free sweep's link sample (module docstring); 1 without free sweeps."""
    if free_cloud is None:
        return 1.0
    distance = float(free_cloud.query(point)[0])
    return 1.0 - math.exp(-0.5 * (distance / FREE_RADIUS) ** 2)


def spread_order(n: int) -> list[int]:
    """0..n-1 middle first, then the middles of the halves, and so on (breadth first), so that
    any prefix of the order spreads over the range: 8 gives 3, 1, 5, 0, 2, 4, 6, 7."""
    order: list[int] = []
    intervals = [(0, n - 1)] if n > 0 else []
    while intervals:
        following = []
        for low, high in intervals:
            middle = (low + high) // 2
            order.append(middle)
            if low <= middle - 1:
                following.append((low, middle - 1))
            if middle + 1 <= high:
                following.append((middle + 1, high))
        intervals = following
    return order


def _vertical_directions(index: int, both: bool) -> tuple[int, ...]:
    """The directions of the vertical sweep at the ``index``-th azimuth: up and down when
    ``both``, else up at the even azimuths and down at the odd."""
    if both:
        return (1, -1)
    return (1,) if index % 2 == 0 else (-1,)


def _sweeps(scene: Scene, azimuthal: int, vertical: int, vertical_both: bool) -> list[Sweep]:
    sweeps: list[Sweep] = []
    a_order = spread_order(azimuthal)
    v_order = spread_order(vertical)
    for base in range(len(scene.bases)):
        region = scene.region_of(base)
        elevations: FloatArray = np.linspace(*region.elevation, azimuthal + 2)[1:-1]
        azimuths: FloatArray = np.linspace(*region.azimuth, vertical + 2)[1:-1]
        # each elevation swept both ways: the two directions touch opposite sides
        pairs = [
            [
                Sweep(base, "azimuthal", float(elevations[i]), *region.azimuth, direction)
                for direction in (1, -1)
            ]
            for i in a_order
        ]
        # a vertical sweep up touches the outline's underside, one down its top
        v = [
            Sweep(base, "vertical", float(azimuths[i]), *region.elevation, direction)
            for i in v_order
            for direction in _vertical_directions(i, vertical_both)
        ]
        # alternate the cases (an elevation's two directions, then an azimuth) so that a prefix
        # holds both
        for k in range(max(len(pairs), len(v))):
            sweeps.extend(pairs[k] if k < len(pairs) else [])
            sweeps.extend(v[k : k + 1])
    if len(scene.bases) > 1:
        # alternate the bases too
        per_base = len(sweeps) // len(scene.bases)
        sweeps = [
            sweeps[b * per_base + k] for k in range(per_base) for b in range(len(scene.bases))
        ]
    return sweeps


def grid_sweeps(scene: Scene) -> list[Sweep]:
    """The scene's grid (module docstring): its held angles evenly inside the region's ranges
    (the ends left out: a sweep along the region's edge), spread-out order."""
    return _sweeps(scene, scene.region.azimuthal_sweeps, scene.region.vertical_sweeps, False)


def candidate_sweeps(scene: Scene) -> list[Sweep]:
    """The next-best strategy's candidates: the grid :data:`CANDIDATE_DENSITY` times finer,
    every sweep in both directions."""
    return _sweeps(
        scene,
        CANDIDATE_DENSITY * scene.region.azimuthal_sweeps,
        CANDIDATE_DENSITY * scene.region.vertical_sweeps,
        True,
    )


@dataclass(frozen=True)
class Choice:
    """A planner's answer: the sweep and why.

    Attributes
    ----------
    sweep : Sweep
    score : float
        The predictive standard deviation at the predicted touch, weighted by the chance to
        touch, with the leading fit's own term and the leading fits' separation when there
        are two (m; module docstring), NaN for a grid choice.
    predicted : array, shape (3,)
        Where the sweep is expected to touch (m, world), NaN for a grid choice.
    std : float
        The surface's predictive std there (m), NaN for a grid choice.
    probability : float
        The chance that the sweep touches, NaN for a grid choice.
    """

    sweep: Sweep
    score: float
    predicted: FloatArray
    std: float = math.nan
    probability: float = math.nan


class NextBestPlanner:
    """Chooses the next sweep from the contacts so far (module docstring).

    Parameters
    ----------
    scene : Scene
        Its bases and region (the objects are not looked at).
    shape : LinkShape
        The link's sagged shape.
    """

    def __init__(self, scene: Scene, shape: LinkShape) -> None:
        self.scene = scene
        self.shape = shape
        self.candidates = candidate_sweeps(scene)
        self.opening = grid_sweeps(scene)
        x = shape.abscissae
        self._samples = np.unique(np.linspace(0, len(x) - 1, _PREDICTION_SAMPLES).astype(int))
        self._swept_cache: dict[Sweep, FloatArray] = {}
        self._fit_cache: dict[int, tuple[ClassFit, dict[Sweep, FloatArray]]] = {}

    def choose(
        self,
        done: Sequence[Sweep],
        surface: ImplicitSurface | None,
        free: Sequence[Sweep] = (),
        leaders: Sequence[ClassFit] = (),
    ) -> Choice | None:
        """The next sweep given the sweeps run so far, the surface fitted to their contacts
        (None until there is one), those of them that touched nothing, and the recognised
        object's primitive fit, or the two leading shape classes' primitive fits when
        recognition abstains between them (module docstring); None when every candidate has
        been run."""
        nan3 = np.full(3, np.nan)
        if surface is None:
            for sweep in self.opening:
                if sweep not in done:
                    return Choice(sweep, float("nan"), nan3)
            surface_free = [c for c in self.candidates if c not in done]
            return Choice(surface_free[0], float("nan"), nan3) if surface_free else None
        left = [c for c in self.candidates if c not in done]
        if not left:
            return None
        # the fits' distances are kept for these leaders only
        self._fit_cache = {id(f): self._fit_cache.get(id(f), (f, {})) for f in leaders}
        free_cloud = None
        if free:
            free_cloud = cKDTree(
                np.concatenate([self._swept(sweep).reshape(-1, 3) for sweep in free])
            )
        best: tuple[float, Choice] | None = None
        fallback: tuple[float, Choice] | None = None
        for sweep in left:
            separation = self.separation(sweep, leaders) if len(leaders) == 2 else 0.0
            fit_term, fit_touches = 0.0, False
            if leaders:
                at, fit_std, deepest = self.fit_outcome(sweep, leaders[0])
                if fit_std > 0.0 and math.isfinite(deepest):
                    # the chance of touching the fit at all, and a free sweep near the fit's
                    # touch (since its recognition, perhaps) against it
                    fit_term = 0.5 * math.erfc(deepest / (math.sqrt(2.0) * fit_std)) * fit_std
                    fit_term *= _unswept(free_cloud, at)
                    fit_touches = deepest <= min(MISS_MARGIN, 2.0 * fit_std)
            point, closest = self._predicted_touch(sweep, surface)
            _, std_at = surface.predict(point[None, :], return_std=True)
            std = float(std_at[0])
            # P(f < 0 there) under the surface's Gaussian prediction: the chance to touch
            probability = 0.5 * math.erfc(closest / (math.sqrt(2.0) * max(std, 1e-12)))
            crowd = sum(
                1
                for d in done
                if d.base == sweep.base
                and d.case == sweep.case
                and d.direction == sweep.direction
                and abs(d.fixed - sweep.fixed) < NEIGHBOUR_ANGLE
            )
            score = probability * std / (1.0 + crowd) * _unswept(free_cloud, point)
            score = math.hypot(score, separation / (1.0 + crowd), fit_term / (1.0 + crowd))
            entry = (score, Choice(sweep, score, point, std, probability))
            if closest > MISS_MARGIN and separation == 0.0 and not fit_touches:
                if fallback is None or score > fallback[0]:
                    fallback = entry
            elif best is None or score > best[0]:
                best = entry
        chosen = best if best is not None else fallback
        assert chosen is not None
        return chosen[1]

    def fit_outcome(self, sweep: Sweep, fit: ClassFit) -> tuple[FloatArray, float, float]:
        """What the leading fit predicts of ``sweep`` (module docstring): the link's sample
        nearest the fit where the sweep first enters it, or where it passes closest when it
        does not (m, world, shape (3,)); the standard deviation of the fit's distance there (m,
        at most :data:`MISS_MARGIN`; 0 when not finite); and the fit's smallest signed distance
        to the link over the sweep (m, < 0 when it predicts a touch). NaN point and distance
        when the link starts inside the fit or a distance is not finite."""
        points = self._swept(sweep)
        distance = self._fit_distances(sweep, fit)
        if not np.all(np.isfinite(distance)) or distance[0].min() < 0.0:
            return np.full(3, np.nan), 0.0, math.nan
        rows = np.nonzero((distance < 0.0).any(axis=1))[0]
        row = int(rows[0]) if rows.size else int(np.argmin(distance.min(axis=1)))
        column = int(np.argmin(distance[row]))
        point = points[row, column]
        std = float(fit.distance_std(point[None, :])[0])
        std = min(std, MISS_MARGIN) if math.isfinite(std) else 0.0
        return point, std, float(distance.min())

    def separation(self, sweep: Sweep, leaders: Sequence[ClassFit]) -> float:
        """How far apart two primitive fits put the outcome of ``sweep`` (m; module docstring).

        Each fit's signed distance to the swept link (the smallest over the link's samples) is
        followed through the sweep; where it first crosses zero (interpolated between angle
        steps) that fit predicts the touch, and the separation is the other fit's distance to
        the link there, the larger of the two when both are touched, at most
        :data:`MISS_MARGIN`; 0 when neither is touched, when the link starts inside either fit
        (no outcome to predict) or when a distance is not finite.
        """
        nearest = [self._fit_distances(sweep, fit).min(axis=1) for fit in leaders]
        rows = len(nearest[0])
        if not all(np.all(np.isfinite(d)) and d[0] >= 0.0 for d in nearest):
            return 0.0
        steps = np.arange(rows, dtype=float)
        gap = 0.0
        for own, other in ((nearest[0], nearest[1]), (nearest[1], nearest[0])):
            inside = np.nonzero(own < 0.0)[0]
            if inside.size:
                k = int(inside[0])
                touch = k - 1 + own[k - 1] / (own[k - 1] - own[k])
                gap = max(gap, abs(float(np.interp(touch, steps, other))))
        return min(gap, MISS_MARGIN)

    def _swept(self, sweep: Sweep) -> FloatArray:
        """The link's samples over the sweep, every :data:`PREDICTION_STEP`, shape (angles,
        samples, 3) (m); kept per sweep, as a candidate is followed at every choice."""
        kept = self._swept_cache.get(sweep)
        if kept is None:
            base = self.scene.base(sweep.base)
            kept = np.stack(
                [
                    self.shape.points(sweep.angles(float(a)), base)[self._samples]
                    for a in sweep.swept_angles(PREDICTION_STEP)
                ]
            )
            self._swept_cache[sweep] = kept
        return kept

    def _fit_distances(self, sweep: Sweep, fit: ClassFit) -> FloatArray:
        """The fit's signed distance (m) at the link's samples over the sweep, shape (angles,
        samples); kept for the fits of the planner's last choice."""
        # keyed by identity: the cache holds the fit, so no other object can take its id
        per_sweep = self._fit_cache.setdefault(id(fit), (fit, {}))[1]
        kept = per_sweep.get(sweep)
        if kept is None:
            points = self._swept(sweep)
            kept = np.asarray(
                PRIMITIVES[fit.name].signed_distance(fit.vector, points.reshape(-1, 3)),
                dtype=float,
            ).reshape(points.shape[:2])
            per_sweep[sweep] = kept
        return kept

    def _predicted_touch(self, sweep: Sweep, surface: ImplicitSurface) -> tuple[FloatArray, float]:
        """The predicted touch point (m) and the smallest f met (m; <= 0 when it touches)."""
        points = self._swept(sweep)
        values = np.asarray(surface.predict(points.reshape(-1, 3))).reshape(points.shape[:2])
        inside = np.nonzero((values < 0).any(axis=1))[0]
        if inside.size:
            row = int(inside[0])
            column = int(np.argmin(values[row]))
        else:
            row, column = divmod(int(np.argmin(values)), points.shape[1])
        return points[row, column], float(values[row, column])
