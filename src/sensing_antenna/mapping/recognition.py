"""Which object was touched: every shape class fitted to the points, scored, and a decision.

Each primitive class (:mod:`~sensing_antenna.mapping.primitives`) is fitted by robust least
squares of each contact's distance to the surface in its standard deviations (below,
"Distance."; scipy.optimize.least_squares, soft-L1 loss so that one bad point does not drag the
fit; several starts per class from the points' principal axes and an algebraic sphere, and
for the axisymmetric classes from axes turned over an icosahedron's and sizes scaled, fitted
first by the Euclidean distance d_i / sigma_i, sigma_i^2 = n_i^T Sigma_i n_i the point's
variance along the surface's normal n_i, then refined, keeping the lowest cost). A user mesh is
registered to the points by iterative closest point (trimesh.registration.icp, from several
starting rotations) and scored the same way with its six pose parameters.

Distance. A contact's point lies on its link's line, far better known across the link than
along it (the abscissa x_c is what the estimate knows least), and the link touched where its
line meets the surface without entering it: tangent to a smooth surface, or passing over an
edge. Over an edge an error along the link moves the point off the surface whichever way it
goes, so the Euclidean distance reads every such point outside, and a box fitted by it grows by
a good part of those errors. So where the link's tangent t_i is known (:class:`LinkLines`), a
contact is taken where its line touches the shape, in its own metric. The line p_i + s t_i is
sampled within :data:`TOUCH_REACH` of the point's standard deviations along t_i, sigma_a
(:data:`TOUCH_SAMPLES` samples; none beyond the link's ends), and m_i is its least distance to
the shape there, at s_m (the least sample, refined where the secants on either side of an edge
meet); a line that enters the shape (m_i < 0) is taken as moved out by m_i, so that it touches.
Its nearest point s_i minimises (d(p_i + s t_i) - min(0, m_i))^2 / sigma_i^2 + s^2 / sigma_a^2,
sigma_i the standard deviation across t_i along the normal there; s_i is found at the least
sample, then between its neighbours on d itself, so that it moves smoothly with the shape. Its
residuals are the distance there beyond the line's depth, e_i = (d_i - min(0, m_i)) /
sqrt(sigma_i^2 + (s_i sigma_t)^2) (sigma_t the tangent's deviation in angle), its place
a_i = s_i / sigma_a, and its line's cut c_i = min(0, m_i) / sigma_m, sigma_m m_i's own spread as
the line moves across itself: sigma_m^2 = g^T Sigma_across g + (s_m sigma_t |g|)^2, g m_i's
gradient; over an edge the faces' normals weighed so that g is across the line,
g = (k_2 n_1 - k_1 n_2) / (k_2 - k_1), k = n . t (a line a distance inside a right-angled edge
reaches only that over up to sqrt(2) deep, and its spread is as much smaller); beside a smooth
surface its normal. Beside a smooth surface tangent to the line d changes along it only at
second order: the nearest point stays by the point and a_i is small, negligible where
kappa sigma_a^2 / 2 is well below sigma_i (kappa the surface's curvature along the line). Over an
edge the nearest point is the edge, and a_i measures the error along the link. A shape grown
until the lines cross it pays for the cut. For a plane along the link this is the Mahalanobis
distance, d^2 / (n^T Sigma n), exactly; a link crossing a plane pays the cut. Limit: t_i is
taken as the covariance's axis (the terms coupling along and across the link are left out). A
contact without a known tangent keeps the Euclidean d_i / sigma_i.

The link's line. A link sweeping towards an object first touches it where the link is tangent
to it: just before, the whole link was outside, and a round link never cuts into what it
pushes. Each contact whose link direction is known (:class:`LinkLines`: the link's unit tangent
at the contact, its standard deviation in angle, and how much link lies behind and beyond the
contact) adds one residual: how far the link's line cuts into the fitted shape beyond the
depth of its nearest point, over its spread, at samples q_k = p + s_k t along the link's stretch
around the contact (up to :data:`LINE_STRETCH` each way, within the link, beyond the nearest
point's reach, whose own cut charges the line within it):
r = min(0, min_k (d(q_k) - min(0, d_i)) / sqrt(sigma_k^2 + (s_k sigma_t)^2)), d_i the distance
at the nearest point ("Distance."; at p without a tangent), sigma_k the point's standard
deviation across the link along d's gradient at q_k and sigma_t the tangent's in angle (the
Euclidean fits that start a class's search: sigma_k along the normal at the point). It is 0
for a convex surface tangent to the link and for an edge the link passes over, and a line
crossing a surface of radius R at an angle beta cuts R (1 - cos beta) deep: a cylinder through
the points a sweeping line left on a box's edges is not tangent to the lines that touched them.

The swept links (``mapping.free_space``): each sweep's link where it passed untouched, and the
link of each contact with no ``ok`` point where it touched, add one residual per sweep or
contact, r_j = min(0, min_k (d(q_k) - a) / sigma_k) over the free samples (a shape reaching
into free space) and max(0, min_k (d(q_k) - a) / sigma_k) over a touching link's (a shape
nowhere near it), a the link's radius.

Score: a Bayesian information criterion, score = chi^2 / c + k ln n, with chi^2 the sum over
the points of -2 log-likelihood of their residuals z_i^2 = e_i^2 + a_i^2 + c_i^2 + r_i^2, e_i
the distance residual ("Distance."; the Euclidean d_i / sigma_i alone without a tangent) up to a
constant, and over the swept
links of their r_j^2 in the same mixture (below), k the class's independent parameters, n the
points, and c >= 1 the overdispersion (Burnham and Anderson, "Model Selection and Multimodel
Inference", 2002, Section 6.2: the reduced chi^2 of the best-fitting class, over N - k, when
above 1, so that points farther from every class than their covariances say, an estimator's
systematic error, weigh less; N counts a distance per point and each a_i by the share of the
point's deviation along the link that its place measures, g^2 / sigma_i^2 over g^2 / sigma_i^2 +
1 / sigma_a^2, g^2 the mean square of d's slopes along the line beside the nearest point: 1 over
an edge, 0 beside a surface tangent to the line, :attr:`ClassFit.measurements`);
c = 1 is BIC. The lowest score wins.
The residuals' distribution is a mixture: a point is right, Gaussian about the surface with its
sigma_i, except with the chance :data:`OUTLIER_FRACTION` that an estimate reported ``ok`` is
wrong and lies anywhere across the points' spread L. Relative to a point on the surface its
part of chi^2 is -2 ln((exp(-z^2 / 2) + e) / (1 + e)), e = exp(-T_i / 2),
T_i = 2 ln((1 - eps) L / (eps sqrt(2 pi) sigma_i)): z^2 near the surface, at most about T_i
far from it (from 13 to 19 for sigma of 5 to 0.3 mm and L of 10 cm), so that one wrong point
costs a class no more than its being wrong costs, and cannot on its own decide between two
shapes (the truncated residual of Torr's robust model selection, "Geometric motion segmentation
and model selection", Phil. Trans. R. Soc. A 356, 1998).

Sizes. Each size of a class's fit carries a standard deviation: the covariance of the fit's
parameters from the evidence's normalised residuals at the fit (the points' e_i, a_i and c_i,
the lines' and the swept links' residuals; not the extent prior, and not the points
counted wrong; :func:`parameter_covariance`: Gauss-Newton's, then the residuals' slopes over one
standard deviation), carried to the sizes, times the square root of the
overdispersion c (the covariance times c is kept with the fit, :attr:`ClassFit.covariance`,
and :meth:`ClassFit.distance_std` carries it to the fitted surface). A size the evidence does
not hold (a sphere's radius from a small cap) is not measured: no deviation. A size whose end no
touch reaches (a box's extent where one face only was touched) is held by the extent prior at
the outermost points: it is reported as a lower bound, three times the deviation of the points
there below the fitted size (:func:`size_std` finds such ends by growing the shape there). A
cone's apex is no such end: the slant places it however far short of it the points stop, and
the prior, which holds it at the points' reach while the class is fitted and scored, would pull
it in by a large part of the gap. So a cone's shape, sizes and covariance are those of its fit
refined with only its base held by the prior, when the evidence measures every size of that
shape or bounds it from below (a size it does not measure says the slant does not place the
apex, and the fit as scored, the smallest the points allow, stands); its chi^2 and RMS stay
those of the fit it was scored by. The points' errors are not independent (a face touched at
its edges reads outward at each), so a size can be off by more than its standard deviation
says; ``benchmarks/eval_explore.py`` measures how often.

The penalty k ln n prefers the simpler of two classes that fit equally, which is right when the
points pin the richer class's extra parameters to the simpler shape (a capsule fitted to a
sphere shrinks its segment to nothing) and wrong when they leave them free: points along one
outline of a torus seen face-on fit a sphere and a whole family of tori alike, and k ln n would
name the sphere with a weight the points never gave it. So the decision also asks whether the
points rule the runner-ups out: a class is a **rival** of the best when its own fit is not
worse by :data:`ABSTAIN_DELTA` in chi^2 / c (the likelihood alone, no penalty: the points do
not reject it) and its fitted shape is a different object, some part of its surface (the
95th percentile of the distances between the two fitted surfaces, both ways) farther from the
best's than :data:`SAME_SHAPE_SIGMAS` times the points' median standard deviation along the
normal. A runner-up whose fitted shape is the best's (the same percentile of their distances
at most the best fit's RMS distance to the points: apart by less than the points scatter),
and whose chi^2 / c is within :data:`ABSTAIN_DELTA` of the best's (the points do not tell the
two apart), is the same object under another class's name; so is a class that holds the best's
as its own special case (``Primitive.holds``: a capsule of no segment is a ball), no farther
from it than :data:`SAME_SHAPE_SIGMAS` of that sigma, whose extra parameters narrow the
points' own scatter no more than they would narrow noise (the F test at :data:`NESTED_LEVEL`).
The two score as one class, the best's score less 2 ln of their weights over the best's. The
decision abstains (``undecided``, naming the best and its rival) when there is a rival, or when
the best runner-up of another shape scores within :data:`ABSTAIN_DELTA` of that.

Confidence: the best class's weight exp(-score / 2) normalised over the classes (the posterior
probability under equal priors in BIC's approximation) with the weights of the classes of its
shape, and, when there is a rival, the best's weight against the rival on the likelihood alone,
1 / (1 + exp(-delta chi^2 / (2 c))). A decision needs the weight a runner-up
:data:`ABSTAIN_DELTA` behind leaves the best, 1 / (1 + exp(-3)) = 0.95: several classes each
that far behind share more than 5 % between them, and the decision abstains. So a named class
always carries a confidence of at least 0.95. An abstention whose best class is refused as the
object's whole shape (a swept link through it, :attr:`ClassFit.n_crossed`) or because no class
fits the points within their deviations (:attr:`Recognition.none_fits`) may carry more.
"""

from __future__ import annotations

import dataclasses
import functools
import itertools
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import trimesh
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import least_squares, minimize_scalar
from scipy.spatial.transform import Rotation
from scipy.stats import binom
from scipy.stats import chi2 as chi2_distribution
from scipy.stats import f as f_distribution

from sensing_antenna.mapping.free_space import FreeSpace
from sensing_antenna.mapping.primitives import (
    PRIMITIVES,
    Primitive,
    distance_gradient,
    local_coordinates,
)
from sensing_antenna.scene.proximity import closest_point, signed_distance

__all__ = [
    "ABSTAIN_DELTA",
    "FIT_CHANCE",
    "FIT_OVERDISPERSION",
    "LINE_STRETCH",
    "OUTLIER_FRACTION",
    "UNDECIDED",
    "ClassFit",
    "LinkLines",
    "PlacedLines",
    "Recognition",
    "confidence_floor",
    "fit_mesh",
    "fit_primitive",
    "no_class_fits",
    "outlier_cap",
    "parameter_covariance",
    "point_chi2",
    "recognise",
    "shape_gap",
    "shape_size",
    "size_std",
]

FloatArray = NDArray[np.float64]

#: A score or chi^2 difference (twice the log Bayes factor or likelihood ratio) below which two
#: classes explain the points equally: 6, where Kass and Raftery (J. Am. Stat. Assoc. 90, 1995,
#: Section 3.2) put "strong" evidence (a factor of 20, a posterior of about 95 % for the better
#: of two under equal priors).
ABSTAIN_DELTA = 6.0

#: The chance below which points of the best-fitting class would lie as far from it as they do
#: (:attr:`Recognition.fit_chance`): with an overdispersion beyond :data:`FIT_OVERDISPERSION`,
#: no class fits them, and none is named (:func:`no_class_fits`).
FIT_CHANCE = 1e-3

#: The overdispersion up to which points are taken to be of the best-fitting class whatever
#: their chi^2 says: their covariances may be narrower than their errors by this much (the
#: realistic device's right answers reach 2), and with many points any such shortfall falls in
#: the chi^2 tail (:func:`no_class_fits`).
FIT_OVERDISPERSION = 2.0

#: Two fitted shapes farther apart than this many of the points' median standard deviations
#: (along the normal) somewhere are different objects: points there would have told them apart.
SAME_SHAPE_SIGMAS = 3.0

#: The level of the F test by which a richer class's narrower scatter is more than noise
#: (:func:`_scatter_narrowed`).
NESTED_LEVEL = 0.95

#: Runner-ups within this many abstention thresholds of the best's score are compared with
#: its shape: beyond, their weight (below exp(-threshold) of the best's) changes nothing.
SAME_SHAPE_SCORE = 2.0

#: Points sampled on each fitted surface to compare two shapes.
SHAPE_SAMPLES = 2000

#: The decision's name when the leading two classes are not told apart.
UNDECIDED = "undecided"

#: Robust loss scale, in standard deviations: residuals beyond 3 sigma count linearly.
ROBUST_SCALE = 3.0

#: Function evaluations per parameter a start may use (twice that for the refined fit): a fit
#: that has not converged by then is on a class the points do not suit, and its BIC says so.
MAX_EVALUATIONS = 100

#: Tolerances of each fit (least_squares' xtol and ftol): a fit stops when a step is shorter than
#: this share of the parameter vector's norm (centre in metres, rotation vector in radians and
#: sizes: micrometres and microradians for a shape within a metre of the head, far below the
#: points' scatter), or when a step lowers the robust cost by less than this share of it. A fit
#: on rough residuals (a contact's nearest point moving from face to face) stops where its steps
#: stall either way; the finer default tolerances (1e-8) cost several times the evaluations there
#: and move the named class's sizes by micrometres (docs/design-notes.md, "Recognition's cost,
#: batched and looser").
FIT_TOLERANCE = 1e-6

#: Largest size a fit may take, in spreads of the points (the diagonal of their bounding box):
#: a closed object ten times larger than all the touches is a plane by another name, and the
#: plane class is there for that.
MAX_SIZE_SPREADS = 10.0

#: Scale of the extent prior (m): a shape's extent along its own axes beyond the points' span
#: there costs (excess / this)^2, as a residual of this many metres would. Points say nothing
#: of a shape beyond them (a cylinder's far end, a box's hidden faces): without the prior those
#: sizes drift freely; with it they stay at the smallest the points allow. A cone's apex is held
#: so too while the class is fitted and scored (a cone free to put its apex far beyond the
#: points mimics other shapes' sides), but its slant places the apex wherever the points stop,
#: so its sizes are read from the fit refined with only its base held (module docstring).
EXTENT_PRIOR = 0.005

#: Smallest size a fit may take (m): a tenth of a millimetre, below any touchable feature.
MIN_SIZE = 1e-4

#: How many of the best fits on the points alone are refined with the link's lines, beside
#: the fits started with them: the lines make the problem rough, and a pose the points alone
#: rank second may suit them best.
REFINED_STARTS = 3

#: The sizes of an axisymmetric class's further starts, as multiples of its first starts'
#: (:func:`_starts`): the algebraic sphere of a patch seen from one side can miss the
#: radius by that much either way.
RESIZED_STARTS = (0.5, 2.0)

#: A registration start (:func:`fit_mesh`) has converged when its points' mean squared distance
#: to the mesh changes by less than this share of their variance in one ICP iteration.
ICP_TOLERANCE = 1e-2

#: Registrations (:func:`fit_mesh`) refined and scored with the links' lines, from the
#: distinct starts that fit the points best.
MESH_CANDIDATES = 8

#: Most points a registration start (:func:`fit_mesh`) is run on.
START_POINTS = 40

#: A direction the points leave a registered mesh free to slide along (:func:`fit_mesh`): its
#: singular value of the points' normal distances against a translation, at most this share of
#: the largest (a cylinder touched on its side slides along its axis, a box's face within it).
FREE_SHARE = 1e-2

#: Shifts along a free direction tried from a registration whose links' lines cross the mesh,
#: over the mesh's largest extent, before the best of them is refined (:func:`fit_mesh`).
FREE_SHIFTS = 9

#: How far along the link each way from a contact its line is checked against a fit (m).
LINE_STRETCH = 0.04

#: Chance that a point reported ``ok`` is wrong, off the surface by more than its covariance
#: allows (the mixture's outlier weight, module docstring): about the share of ``ok`` estimates
#: over 1 cm off in the simulated campaigns and explorations, which stays below it.
OUTLIER_FRACTION = 0.01

#: How far beyond the points' bounding box (m, plus half their spread) free space is checked
#: against a fit: a fitted shape reaches beyond its points by its hidden side at most.
FREE_MARGIN = 0.02

#: A free-space sample farther outside a fit than this (m) at the start of a refinement stays
#: out of it while the refinement moves the shape (the score checks every sample).
FREE_ACTIVE = 0.01

#: Step (m or rad) of the central differences of a fit's Jacobian for its sizes' standard
#: deviations: a micrometre, far below the points' scatter and far above rounding.
JACOBIAN_STEP = 1e-6

#: Rounds of measuring a fit's information again over the range its parameters are uncertain
#: by (:func:`parameter_covariance`).
SECANT_ROUNDS = 2

#: Eigenvalues of J^T J below this fraction of the largest are directions the points do not
#: hold (a box's hidden extent with its centre): sizes moving along them are free.
EIGEN_FLOOR = 1e-12

#: How far along the link from a contact its nearest point is sought, and its line's cut, in the
#: point's standard deviations along the link: farther, the point is not there by its covariance.
TOUCH_REACH = 4.0

#: Samples of the line over that reach (odd: one at the point), an eighth of a standard
#: deviation apart (module docstring, "Distance.").
TOUCH_SAMPLES = 65

#: Each line's samples, in the point's standard deviations along the link.
_TOUCH_GRID = np.linspace(-TOUCH_REACH, TOUCH_REACH, TOUCH_SAMPLES)

#: Rounds and points per round of the search for a contact's nearest point along its line
#: between the samples beside the least: each round narrows it to a quarter.
_REFINE_ROUNDS = 4
_REFINE_POINTS = 9

#: Distances (m) closer than this to a line's least are as least (rounding).
_TIE = 1e-12

#: Step (m) of the central differences of d's gradient (beside a line's least distance, at the
#: link line's samples).
_GRADIENT_STEP = 1e-6

#: Where along that stretch, as fractions of it.
_LINE_FRACTIONS = (0.125, 0.25, 0.5, 1.0)


@dataclass(frozen=True)
class LinkLines:
    """The link's line at each contact, for the tangency residual (module docstring).

    Attributes
    ----------
    tangents : array, shape (n, 3)
        The link's unit tangent at each contact, from the base towards the tip (world); a row
        of NaN where it is not known (no residual for that contact).
    std : array, shape (n,)
        The tangent's standard deviation in angle (rad).
    behind, beyond : array, shape (n,)
        Link length (m) between the base and the contact, and between the contact and the tip.
    """

    tangents: FloatArray
    std: FloatArray
    behind: FloatArray
    beyond: FloatArray

    def __post_init__(self) -> None:
        n = len(np.asarray(self.tangents).reshape(-1, 3))
        object.__setattr__(self, "tangents", np.asarray(self.tangents, float).reshape(n, 3))
        for name in ("std", "behind", "beyond"):
            value = np.asarray(getattr(self, name), dtype=float).reshape(-1)
            if len(value) != n:
                raise ValueError(f"LinkLines.{name}: {len(value)} values for {n} tangents")
            object.__setattr__(self, name, value)

    def samples(self, points: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Points along each line (m), shape (n, k, 3), and their signed arc lengths s (m),
        shape (n, k); s is NaN where the link does not reach or the tangent is unknown."""
        steps = LINE_STRETCH * np.array([*(-f for f in _LINE_FRACTIONS), *_LINE_FRACTIONS])
        arc = self.within(np.broadcast_to(steps, (len(points), len(steps))))
        along = np.nan_to_num(arc)[:, :, None] * np.nan_to_num(self.tangents)[:, None, :]
        return np.asarray(points[:, None, :] + along), arc

    @property
    def known(self) -> NDArray[np.bool_]:
        """Whether each contact's tangent and its deviation are known, shape (n,)."""
        return np.asarray(np.all(np.isfinite(self.tangents), axis=1) & np.isfinite(self.std))

    def within(self, arc: FloatArray) -> FloatArray:
        """Arc lengths s (m, shape (n, k)) with NaN where the link does not reach (beyond its
        base or tip) or the tangent is unknown."""
        arc = np.array(arc, dtype=float)
        arc[(arc < 0) & (-arc > self.behind[:, None])] = np.nan
        arc[(arc > 0) & (arc > self.beyond[:, None])] = np.nan
        arc[~self.known] = np.nan
        return arc

    def residuals(
        self,
        distance: Callable[[FloatArray], FloatArray],
        points: FloatArray,
        sigma: FloatArray,
        touched: FloatArray | None = None,
        reach: FloatArray | None = None,
        across: FloatArray | None = None,
    ) -> FloatArray:
        """r_i (module docstring), shape (n,), for a signed distance function of (m, 3) points
        and the points' standard deviations across the link along the surface's normal (m,
        shape (n,)); ``touched``, ``reach`` and ``across`` as in
        :meth:`PlacedLines.residuals`."""
        return self.placed(points).residuals(distance, sigma, touched, reach, across)

    def placed(self, points: FloatArray) -> PlacedLines:
        """The lines at these contacts (m, shape (n, 3)), sampled once: a fit evaluates its
        residuals many times over the same points."""
        points = np.asarray(points, dtype=float).reshape(-1, 3)
        if len(points) != len(self.tangents):
            raise ValueError(f"{len(self.tangents)} link lines for {len(points)} points")
        samples, arc = self.samples(points)
        slope_variance = (np.nan_to_num(arc) * self.std[:, None]) ** 2
        return PlacedLines(points, samples.reshape(-1, 3), arc, slope_variance)


@dataclass(frozen=True)
class PlacedLines:
    """:class:`LinkLines` sampled at a set of contacts (:meth:`LinkLines.placed`).

    Attributes
    ----------
    points : array, shape (n, 3)
        The contacts (m).
    samples : array, shape (n * k, 3)
        Points along each line (m), k per contact.
    arc : array, shape (n, k)
        Their signed arc lengths (m); NaN where the link does not reach.
    slope_variance : array, shape (n, k)
        (s sigma_t)^2 (m^2): how far the line's angle error moves each sample across it.
    blocks : int
        How many copies of the same contacts it holds, one after another (:meth:`tiled`).
    """

    points: FloatArray
    samples: FloatArray
    arc: FloatArray
    slope_variance: FloatArray
    blocks: int = 1

    def tiled(self, copies: int) -> PlacedLines:
        """The lines ``copies`` times over, one block after another (a batch of shapes whose
        distance function reads the queries block by block, as :meth:`residuals` builds them:
        each block's together and as many)."""
        if copies == 1:
            return self
        points, samples, arc, slope_variance = (
            np.concatenate([a] * copies)
            for a in (self.points, self.samples, self.arc, self.slope_variance)
        )
        return PlacedLines(points, samples, arc, slope_variance, copies)

    def residuals(
        self,
        distance: Callable[[FloatArray], FloatArray],
        sigma: FloatArray,
        touched: FloatArray | None = None,
        reach: FloatArray | None = None,
        across: FloatArray | None = None,
    ) -> FloatArray:
        """r_i (module docstring), shape (n,): :meth:`LinkLines.residuals` at these contacts;
        the depth allowed is d at each point's nearest point along its line, ``touched`` (m,
        shape (n,)), when given, else d at the point itself; samples within ``reach`` (m,
        shape (n,)) of the point are left out (the nearest point's own cut charges them).
        With the points' covariances across the link, ``across`` (m^2, shape (n, 3, 3)), each
        sample's depth is over its own deviation, along d's gradient there, instead of
        ``sigma``."""
        n, k = self.arc.shape
        if n == 0:
            return np.zeros(0)
        at_line = distance(self.samples).reshape(n, k)
        own = np.minimum(distance(self.points) if touched is None else touched, 0.0)
        spread = np.sqrt(sigma[:, None] ** 2 + self.slope_variance)
        counted = np.isfinite(self.arc)
        if reach is not None:
            counted &= np.abs(np.nan_to_num(self.arc)) > reach[:, None]
        depth = at_line - own[:, None]
        if across is None:
            deeper = np.where(counted, depth / spread, np.inf)
            return np.asarray(np.minimum(deeper.min(axis=1), 0.0))
        # each sample that cuts in, over its own deviation along d's gradient there (found in
        # every block at each sample that cuts in in any: as many queries per block)
        cut = counted & (depth < 0.0)
        if not np.any(cut):
            return np.zeros(n)
        anywhere = cut.reshape(self.blocks, -1, k).any(axis=0)
        row, col = np.nonzero(np.tile(anywhere, (self.blocks, 1)))
        gradient = distance_gradient(
            distance, self.samples.reshape(n, k, 3)[row, col], _GRADIENT_STEP
        )
        own = cut[row, col]
        row, col, gradient = row[own], col[own], gradient[own]
        # a distance's gradient is a unit normal but where two sides meet (a medial axis,
        # deep inside): there the deviation along the nearest point's normal stands
        size = np.linalg.norm(gradient, axis=1)
        normal = gradient / np.maximum(size, 1e-6)[:, None]
        variance = np.einsum("ni,nij,nj->n", normal, across[row], normal)
        variance = variance + self.slope_variance[row, col] * np.sum(normal**2, axis=1)
        own_deviation = np.full((n, k), np.inf)
        own_deviation[row, col] = np.where(
            size > 0.5, np.sqrt(np.maximum(variance, 1e-18)), spread[row, col]
        )
        cuts = np.where(np.isfinite(own_deviation), depth / own_deviation, 0.0)
        weighed = np.isfinite(sigma)  # a point that weighs nothing keeps 0
        return np.asarray(np.where(weighed, np.minimum(cuts.min(axis=1), 0.0), 0.0))


@dataclass(frozen=True)
class ClassFit:
    """One class's fit to the points.

    Attributes
    ----------
    name : str
        Class name (``sphere``, ...; ``mesh:NAME`` for a user mesh).
    parameters : Mapping[str, float]
        Fitted parameters (m, rad; a mesh: its 4 x 4 pose as ``m00`` ... ``m23``).
    sizes : Mapping[str, float]
        The class's sizes (m).
    size_std : Mapping[str, float]
        Each size's standard deviation (m; module docstring, "Sizes."), inf for a size the
        points do not measure or only bound from below (:attr:`size_at_least`); empty for a
        user mesh, whose size is its own.
        :func:`fit_primitive` gives it for the points' own covariances, :func:`recognise`
        widened by the overdispersion.
    covariance : array, shape (len(vector), len(vector))
        The covariance of :attr:`vector` (module docstring, "Sizes."; units of the
        parameters squared; :func:`parameter_covariance`), a direction the evidence does not
        hold at a variance far beyond any size; shape (0, 0) for a user mesh. Widened by the
        overdispersion in :func:`recognise`, as the sizes' deviations are.
    size_at_least : Mapping[str, float]
        For each size the extent prior holds whose end nothing holds (a box's hidden face), the
        lower bound the points give it (m): the fitted size less three times the largest
        deviation of the points at that end, since the end was left at the outermost, noisy,
        points (widened by the overdispersion in :func:`recognise`).
    rms : float
        RMS of the point-to-surface distances (m) of the points it does not count wrong (all
        of them when it counts every one wrong).
    chi2 : float
        sum over the points of their part of chi^2 (:func:`point_chi2`, of z_i^2 = (d_i /
        sigma_i)^2 + r_i^2; dimensionless) and the swept links' parts.
    bic : float
        chi2 + dof ln n (the score when c = 1).
    dof : int
        Independent parameters.
    n_points : int
        Points fitted.
    measurements : float
        The residuals the points' chi^2 sums, counted for the overdispersion: one distance
        per point, and each place along its line by the share of the point's variance along
        the link that it measures (module docstring, "Distance." and "Score"); n_points when
        NaN.
    line_chi2 : float
        sum r_i^2, the link lines' residuals before the mixture (0 without lines).
    swept_chi2 : float
        sum r_j^2, the swept links' residuals (free space and touches) before the mixture
        (0 without them).
    weight : float
        Weight exp(-score / 2) among the classes compared (0 to 1); NaN until compared.
    score : float
        chi2 / c + dof ln n (module docstring); NaN until compared.
    n_wrong : int
        Points the mixture counts wrong at the fit: z_i^2 beyond their :func:`outlier_cap`
        (more likely wrong estimates than points of this shape).
    wrong : tuple of int
        Which: their indices among the points fitted, farthest first.
    wrong_chi2 : float
        Their part of :attr:`chi2` (each near its cap).
    wrong_measurements : float
        Their part of :attr:`measurements`.
    n_crossed : int
        Swept links the fit contradicts beyond their :func:`outlier_cap`: a link that swept
        untouched through the fitted shape, or one that touched nowhere near it. Such a fit is
        not named (:func:`recognise`): the object is not one such shape (two objects, a gap
        between parts), or a sweep is wrong.
    free_ends : tuple of array
        The ends no evidence holds (:func:`size_std`): the change of :attr:`vector` per metre
        each grows by.
    """

    name: str
    parameters: Mapping[str, float]
    sizes: Mapping[str, float]
    rms: float
    chi2: float
    bic: float
    dof: int
    n_points: int
    line_chi2: float = 0.0
    swept_chi2: float = 0.0
    weight: float = math.nan
    score: float = math.nan
    size_std: Mapping[str, float] = field(default_factory=dict)
    size_at_least: Mapping[str, float] = field(default_factory=dict)
    vector: FloatArray = field(default_factory=lambda: np.zeros(0), compare=False, repr=False)
    covariance: FloatArray = field(
        default_factory=lambda: np.zeros((0, 0)), compare=False, repr=False
    )
    mesh: trimesh.Trimesh | None = field(default=None, compare=False, repr=False)
    measurements: float = math.nan
    n_wrong: int = 0
    wrong: tuple[int, ...] = ()
    wrong_chi2: float = 0.0
    wrong_measurements: float = 0.0
    n_crossed: int = 0
    free_ends: tuple[FloatArray, ...] = field(default=(), compare=False, repr=False)

    @property
    def counted(self) -> float:
        """:attr:`measurements`, n_points where it is not known."""
        return float(self.measurements if math.isfinite(self.measurements) else self.n_points)

    def distances(self, points: ArrayLike) -> FloatArray:
        """Distance (m) of ``points`` (m, shape (n, 3)) from the fitted surface, shape (n,)."""
        return _surface_distance(self, np.asarray(points, dtype=float).reshape(-1, 3))

    def distance_std(self, points: ArrayLike) -> FloatArray:
        """Standard deviation (m) of the fitted shape's signed distance at each of ``points``
        (m, shape (n, 3)), from :attr:`covariance`: how far the fitted surface may lie from
        where it is drawn there, shape (n,). Where the surface moves with a direction the
        evidence does not hold (a cylinder's untouched end: one of :attr:`free_ends`, the
        distance moving at least half as fast as the end) it is inf; NaN for a user mesh or a
        covariance that is not finite (the evidence holds no direction)."""
        q = np.asarray(points, dtype=float).reshape(-1, 3)
        model = PRIMITIVES.get(self.name)
        n = len(self.vector)
        if model is None or self.covariance.shape != (n, n):
            return np.full(len(q), np.nan)
        if not np.all(np.isfinite(self.covariance)):
            return np.full(len(q), np.nan)
        std = _carried(lambda v: model.signed_distance(v, q), self.vector, self.covariance)
        here = model.signed_distance(self.vector, q)
        for change in self.free_ends:
            moved = model.signed_distance(self.vector + JACOBIAN_STEP * change, q) - here
            std = np.where(np.abs(moved) >= 0.5 * JACOBIAN_STEP, np.inf, std)
        return np.asarray(std)

    @property
    def wrong_chance(self) -> float:
        """The chance that :attr:`n_wrong` or more of the points are wrong estimates when each
        is wrong with :data:`OUTLIER_FRACTION` (binomial upper tail; 1 when none is): a small
        one says the points are not all of this shape (another object among them, points
        misplaced)."""
        if self.n_wrong <= 0:
            return 1.0
        return float(binom.sf(self.n_wrong - 1, self.n_points, OUTLIER_FRACTION))

    def sizes_known(self, within: float) -> bool:
        """Whether every size is known to within the share ``within`` of itself (0.05: 5 %):
        twice its standard deviation (about a 95 % interval's half-width) at most that share of
        it, each size on its own (a capsule's short length as its radius). A size the points do
        not measure or only bound from below is not known; a plane (no sizes) and a user mesh
        (no primitive class: registered at its own size) are."""
        if self.name not in PRIMITIVES:
            return True
        return all(
            2.0 * self.size_std.get(name, math.inf) <= within * size
            for name, size in self.sizes.items()
        )

    def sizes_text(self) -> str:
        """The sizes in mm for reading: ``radius 18.7 +- 1.0 mm``, a size that is only a lower
        bound as ``height at least 147.2 mm``, one the points do not measure as ``radius 251.2
        mm (not measured)``, a user mesh's as its own; ``-`` without sizes."""
        parts = []
        for name, value in self.sizes.items():
            std = self.size_std.get(name)
            if name in self.size_at_least:
                parts.append(f"{name} at least {1000 * self.size_at_least[name]:.1f} mm")
            elif std is None:
                parts.append(f"{name} {1000 * value:.1f} mm")
            elif math.isfinite(std):
                digits = 1 if std >= 5e-5 else 2
                parts.append(f"{name} {1000 * value:.{digits}f} +- {1000 * std:.{digits}f} mm")
            else:
                parts.append(f"{name} {1000 * value:.1f} mm (not measured)")
        return ", ".join(parts) or "-"

    def to_dict(self) -> dict[str, Any]:
        """JSON-able (SI units)."""
        return {
            "class": self.name,
            "parameters": {k: float(v) for k, v in self.parameters.items()},
            "sizes": {k: float(v) for k, v in self.sizes.items()},
            # null: a size the points do not measure
            "size_std": {
                k: float(v) if math.isfinite(v) else None for k, v in self.size_std.items()
            },
            "size_at_least": {k: float(v) for k, v in self.size_at_least.items()},
            "rms_m": float(self.rms),
            "chi2": float(self.chi2),
            "line_chi2": float(self.line_chi2),
            "swept_chi2": float(self.swept_chi2),
            "bic": float(self.bic),
            "score": None if math.isnan(self.score) else float(self.score),
            "dof": self.dof,
            "n_points": self.n_points,
            "measurements": self.counted,
            "n_wrong": self.n_wrong,
            "wrong": list(self.wrong),
            "n_crossed": self.n_crossed,
            "weight": None if math.isnan(self.weight) else float(self.weight),
        }


@dataclass(frozen=True)
class Recognition:
    """The decision and every class's fit.

    Attributes
    ----------
    decision : str
        The best class, or ``undecided``.
    fits : tuple of ClassFit
        Every class, best (lowest score) first, with weights.
    candidates : tuple of str
        The best class and its rival, or the best runner-up of another shape (one name when
        there is none).
    delta_score : float
        Score of the best runner-up of another shape minus the best's, that less 2 ln of the
        weight of the best and its shape's runner-ups (:attr:`same_shape`) over the best's
        (inf without one).
    confidence : float
        The best class's weight with its shape's runner-ups' (0 to 1; against its rival when
        there is one).
    threshold : float
        The abstention threshold used.
    overdispersion : float
        c, the reduced chi^2 of the best-fitting class when above 1 (else 1).
    fit_chance : float
        The chance that points of the best-fitting class, scattered as their covariances say
        and wrong as often as estimates are, lie as far from it as these do (:func:`_fit_chance`:
        the chi^2 of the points it takes, and with them the count it takes as wrong): below
        :data:`FIT_CHANCE`, with an overdispersion beyond :data:`FIT_OVERDISPERSION`, no class
        fits them and none is named (:attr:`none_fits`).
    rival : str or None
        A class the points do not rule out that is a different shape from the best's.
    same_shape : tuple of str
        Runner-ups whose fitted shape is the best's: their weight counts with the best's.
    runner_up : str or None
        The best runner-up of another shape, the one :attr:`delta_score` is to (None without
        one).
    """

    decision: str
    fits: tuple[ClassFit, ...]
    candidates: tuple[str, ...]
    delta_score: float
    confidence: float
    threshold: float
    overdispersion: float = 1.0
    fit_chance: float = 1.0
    rival: str | None = None
    same_shape: tuple[str, ...] = ()
    runner_up: str | None = None

    @property
    def best(self) -> ClassFit:
        """The lowest-score fit (even when the decision abstains)."""
        return self.fits[0]

    @property
    def named(self) -> ClassFit | None:
        """The fit of the class the decision names; None when it abstains."""
        return None if self.undecided else self.best

    @property
    def undecided(self) -> bool:
        """True when the decision abstains."""
        return self.decision == UNDECIDED

    @property
    def none_fits(self) -> bool:
        """True when no class fits the points within their deviations (:func:`no_class_fits`):
        recognition then names none."""
        return no_class_fits(self.fit_chance, self.overdispersion)

    @property
    def confidence_floor(self) -> float:
        """The confidence a decision needs, 1 / (1 + exp(-threshold / 2)) (0.95 at 6)."""
        return confidence_floor(self.threshold)

    def to_dict(self) -> dict[str, Any]:
        """JSON-able (SI units)."""
        return {
            "decision": self.decision,
            "candidates": list(self.candidates),
            "delta_score": None if math.isinf(self.delta_score) else float(self.delta_score),
            "confidence": float(self.confidence),
            "abstain_delta": float(self.threshold),
            "overdispersion": float(self.overdispersion),
            "fit_chance": float(self.fit_chance),
            "rival": self.rival,
            "same_shape": list(self.same_shape),
            "runner_up": self.runner_up,
            "fits": [f.to_dict() for f in self.fits],
        }


def no_class_fits(fit_chance: float, overdispersion: float) -> bool:
    """True when chance scatters points so far from the best-fitting class less often than
    :data:`FIT_CHANCE` (``fit_chance``) and they lie beyond what covariances narrower than the
    errors make (``overdispersion`` above :data:`FIT_OVERDISPERSION`)."""
    return fit_chance < FIT_CHANCE and overdispersion > FIT_OVERDISPERSION


def _fit_chance(fit: ClassFit) -> float:
    """The chance that points of ``fit``'s shape, scattered as their covariances say and wrong
    with :data:`OUTLIER_FRACTION`, lie as far from it as these do (:attr:`Recognition.fit_chance`):
    the smaller of the tail of its chi^2 without the points it counts wrong (over their
    measurements less its parameters; the swept links' part, mostly none, counted in without
    degrees of freedom of its own) and that tail combined with the chance of as many wrong
    (:attr:`ClassFit.wrong_chance`) by Fisher's method (-2 ln of their product, chi^2 with 4
    degrees of freedom): a few points off a shape that fits the rest, each of which wrong
    estimates could make, are as telling together as far as they lie."""
    taken = max(fit.counted - fit.wrong_measurements - fit.dof, 1.0)
    fitted = float(chi2_distribution.sf(fit.chi2 - fit.wrong_chi2, taken))
    product = max(fitted, 1e-300) * max(fit.wrong_chance, 1e-300)
    return min(fitted, float(chi2_distribution.sf(-2.0 * math.log(product), 4)))


def _normal_sigma(covariances: FloatArray, normals: FloatArray) -> FloatArray:
    """sigma_i = sqrt(n_i^T Sigma_i n_i) (m), shape (n,)."""
    variance = np.einsum("ni,nij,nj->n", normals, covariances, normals)
    return np.asarray(np.sqrt(np.maximum(variance, 1e-18)))


def _isotropic_sigma(covariances: FloatArray) -> FloatArray:
    return np.asarray(np.sqrt(np.trace(covariances, axis1=1, axis2=2) / 3.0))


@dataclass(frozen=True)
class _Touch:
    """Each contact's line, for its nearest point along it and its cut into a shape (module
    docstring, "Distance."): the line p_i + s t_i sampled over s within :data:`TOUCH_REACH`
    standard deviations of the point along the link, and the point's covariance across the
    link. A contact without a known tangent has one sample, the point itself, and its whole
    covariance.

    Attributes
    ----------
    points : array, shape (n, 3)
        The contacts (m).
    tangents : array, shape (n, 3)
        The link's unit tangent at each (zeros where unknown).
    along : array, shape (n,)
        The point's standard deviation along the tangent (m; inf where unknown).
    slope : array, shape (n,)
        The tangent's standard deviation in angle (rad; 0 where unknown).
    arc : array, shape (n, k)
        The samples' offsets s along the line (m), NaN beyond the link.
    across : array, shape (n, 3, 3)
        The covariance across the tangent, (I - t t^T) Sigma (I - t t^T) (m^2; Sigma where the
        tangent is unknown).
    """

    points: FloatArray
    tangents: FloatArray
    along: FloatArray
    slope: FloatArray
    arc: FloatArray
    across: FloatArray
    # the samples within the link (m, shape (m, 3)) and where they sit in arc's flat order
    samples: FloatArray = field(init=False, repr=False)
    flat: NDArray[np.intp] = field(init=False, repr=False)
    filled: FloatArray = field(init=False, repr=False)  # arc, 0 beyond the link

    def __post_init__(self) -> None:
        flat = np.flatnonzero(np.isfinite(self.arc))
        rows = flat // self.arc.shape[1]
        object.__setattr__(self, "filled", np.nan_to_num(self.arc))
        placed = self.points[rows] + self.arc.reshape(-1)[flat, None] * self.tangents[rows]
        object.__setattr__(self, "flat", flat)
        object.__setattr__(self, "samples", placed)

    @classmethod
    def of(cls, points: FloatArray, covariances: FloatArray, lines: LinkLines | None) -> _Touch:
        n = len(points)
        known = lines.known if lines is not None else np.zeros(n, dtype=bool)
        tangents = np.zeros((n, 3)) if lines is None else np.nan_to_num(lines.tangents)
        tangents[~known] = 0.0
        slope = np.where(known, np.nan_to_num(lines.std), 0.0) if lines is not None else np.zeros(n)
        variance = np.einsum("ni,nij,nj->n", tangents, covariances, tangents)
        along = np.where(known, np.sqrt(np.maximum(variance, 1e-18)), np.inf)
        arc = np.where(
            known[:, None], np.nan_to_num(along, posinf=0.0)[:, None] * _TOUCH_GRID, np.nan
        )
        if lines is not None:
            arc = lines.within(arc)
        arc[~known, TOUCH_SAMPLES // 2] = 0.0  # the point itself
        projector = np.eye(3) - np.einsum("ni,nj->nij", tangents, tangents)
        across = projector @ covariances @ projector
        return cls(points, tangents, along, slope, arc, across)

    def tiled(self, copies: int) -> _Touch:
        """The contacts ``copies`` times over, one block after another: for a batch of shapes,
        whose distance function reads the queries block by block (every query array below is
        built contact by contact, so each block's queries come together and equally many)."""
        if copies == 1:
            return self
        fields = (self.points, self.tangents, self.along, self.slope, self.arc, self.across)
        return _Touch(*(np.concatenate([a] * copies) for a in fields))

    @property
    def reach(self) -> FloatArray:
        """How far along each line its samples reach (m, shape (n,); 0 without a tangent)."""
        return np.asarray(np.where(np.isfinite(self.along), TOUCH_REACH * self.along, 0.0))

    @property
    def spacing(self) -> FloatArray:
        """The spacing of each line's samples (m, shape (n,); 0 without a tangent)."""
        step = _TOUCH_GRID[1] - _TOUCH_GRID[0]
        return np.asarray(np.where(np.isfinite(self.along), step * self.along, 0.0))

    def where(self, shift: FloatArray) -> FloatArray:
        """The points moved along their lines by ``shift`` (m, shape (n,)), shape (n, 3)."""
        return self.where_all(shift[:, None])

    def across_sigma(self, normals: FloatArray) -> FloatArray:
        """sqrt(n_i^T Sigma_across n_i) (m), shape (n,), for unit normals (n, 3)."""
        return _normal_sigma(self.across, normals)

    def sampled(self, distance: Callable[[FloatArray], FloatArray]) -> FloatArray:
        """d at each line's samples (m), shape (n, k); inf beyond the link."""
        values = np.full(self.arc.size, np.inf)
        values[self.flat] = distance(self.samples)
        return values.reshape(self.arc.shape)

    def nearest(
        self,
        distance: Callable[[FloatArray], FloatArray],
        values: FloatArray,
        across: FloatArray,
        offset: FloatArray,
    ) -> tuple[FloatArray, FloatArray]:
        """Where along each line the cost (d(p + s t) - offset)^2 / across^2 + s^2 / sigma_a^2
        is least (m, shape (n,)), and the mean square of the distance's slopes along the line on
        either side of the least sample (shape (n,)), from the samples' ``values``
        (:meth:`sampled`, less ``offset``, m, shape (n,)) and the deviations ``across`` (m;
        inf: the point itself): the least sample, then the least between its neighbours on d
        itself (:meth:`refined`), so that the place moves smoothly with the shape (a sampled
        place moves in steps, and a fit's slopes would follow the steps)."""
        n, k = values.shape
        rows = np.arange(n)
        weight = np.where(np.isfinite(across), 1.0 / np.maximum(across, 1e-12) ** 2, 0.0)
        along = np.where(np.isfinite(self.along), self.along, 1.0)
        arc = self.filled
        finite = np.isfinite(values)
        cost = np.where(
            finite,
            weight[:, None] * np.where(finite, values, 0.0) ** 2 + (arc / along[:, None]) ** 2,
            np.inf,
        )
        j = np.argmin(cost, axis=1)
        left, right = np.maximum(j - 1, 0), np.minimum(j + 1, k - 1)
        left = np.where(np.isfinite(cost[rows, left]), left, j)
        right = np.where(np.isfinite(cost[rows, right]), right, j)
        shift = self.refined(distance, offset, weight, along, arc[rows, left], arc[rows, right])
        before = np.where(left < j, arc[rows, j] - arc[rows, left], 1.0)
        after = np.where(j < right, arc[rows, right] - arc[rows, j], 1.0)
        with np.errstate(invalid="ignore"):
            slopes = [
                (values[rows, j] - values[rows, left]) / before,
                (values[rows, right] - values[rows, j]) / after,
            ]
        known = [(left < j) & np.isfinite(slopes[0]), (j < right) & np.isfinite(slopes[1])]
        count = known[0].astype(float) + known[1]
        square = np.where(known[0], slopes[0], 0.0) ** 2 + np.where(known[1], slopes[1], 0.0) ** 2
        return shift, np.divide(square, count, out=np.zeros(n), where=count > 0)

    def refined(
        self,
        distance: Callable[[FloatArray], FloatArray],
        offset: FloatArray,
        weight: FloatArray,
        along: FloatArray,
        low: FloatArray,
        high: FloatArray,
    ) -> FloatArray:
        """The least of (d(p + s t) - offset)^2 weight + (s / along)^2 over s in [low, high]
        (m, each shape (n,)): :data:`_REFINE_ROUNDS` rounds of :data:`_REFINE_POINTS` evenly spaced
        points, each round between the least one's neighbours, then the vertex of the parabola
        through the last round's least and its neighbours."""
        n = len(low)
        rows = np.arange(n)
        grid = np.linspace(0.0, 1.0, _REFINE_POINTS)
        a, b = low, high
        for _ in range(_REFINE_ROUNDS):
            s = a[:, None] + (b - a)[:, None] * grid  # shape (n, m)
            d = np.asarray(distance(self.where_all(s)), dtype=float).reshape(s.shape)
            d = d - offset[:, None]
            cost = weight[:, None] * d**2 + (s / along[:, None]) ** 2
            i = np.clip(np.argmin(cost, axis=1), 1, _REFINE_POINTS - 2)
            a, b = s[rows, i - 1], s[rows, i + 1]
        c0, c1, c2 = cost[rows, i - 1], cost[rows, i], cost[rows, i + 1]
        middle, spacing = s[rows, i], 0.5 * (b - a)
        curve = c0 - 2.0 * c1 + c2
        ok = (spacing > 0.0) & (curve > 0.0)
        step = np.divide(spacing * (c0 - c2), 2.0 * curve, out=np.zeros(n), where=ok)
        return np.asarray(middle + np.clip(step, -spacing, spacing))

    def where_all(self, shift: FloatArray) -> FloatArray:
        """The points moved along their lines by each of ``shift`` (m, shape (n, m)), shape
        (n * m, 3)."""
        moved = self.points[:, None, :] + shift[:, :, None] * self.tangents[:, None, :]
        return np.asarray(moved.reshape(-1, 3))

    @staticmethod
    def least(values: FloatArray, arc: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Each line's least distance to the shape (m; negative where it cuts in) and where
        along it (m), both shape (n,), from the samples' ``values`` at offsets ``arc``: the least
        sample (of samples within :data:`_TIE` of it, the nearest the point: along a line
        parallel to a plane every sample is least), refined where the line passes over an edge
        (the secants on either side met)."""
        n, k = values.shape
        rows = np.arange(n)[:, None]
        lowest = np.min(values, axis=1, keepdims=True)
        tied = values <= lowest + _TIE
        nearest = np.argmin(np.where(tied, np.abs(np.nan_to_num(arc)), np.inf), axis=1)
        index = nearest[:, None] + np.arange(-2, 3)
        inside = (index >= 0) & (index < k)
        clipped = np.clip(index, 0, k - 1)
        v = np.where(inside, values[rows, clipped], np.inf)  # the least sample and 2 each side
        s = np.where(inside, np.nan_to_num(arc[rows, clipped]), 0.0)
        least, shift = v[:, 2], s[:, 2]
        with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
            # the secant through samples i, i + 1 met with that through i + 2, i + 3 (i = 0, 1):
            # exact where the distance is straight on either side of an edge
            slope = np.diff(v, axis=1) / np.diff(s, axis=1)  # shape (n, 4)
            for i in (0, 1):
                k1, k2 = slope[:, i], slope[:, i + 2]
                ok = np.all(np.isfinite(v[:, i : i + 4]), axis=1) & (k2 - k1 > 1e-9)
                cross = (v[:, i + 2] - v[:, i] + k1 * s[:, i] - k2 * s[:, i + 2]) / np.where(
                    ok, k1 - k2, 1.0
                )
                ok &= (cross >= s[:, 1]) & (cross <= s[:, 3])
                value = v[:, i] + k1 * (cross - s[:, i])
                better = ok & (value < least)
                least = np.where(better, value, least)
                shift = np.where(better, cross, shift)
        return least, shift

    def least_sigma(
        self, distance: Callable[[FloatArray], FloatArray], shift: FloatArray
    ) -> FloatArray:
        """The standard deviation (m, shape (n,)) of each line's least distance to the shape,
        found at ``shift`` along it (m, shape (n,)): sqrt(g^T Sigma_across g + (s_m sigma_t
        |g|)^2), g the least distance's gradient as the line moves across itself, from d's
        gradients n_1, n_2 a sample before and after it (central differences):
        g = (k_2 n_1 - k_1 n_2) / (k_2 - k_1), k = n . t, the weighing of the two that is
        across the line (over an edge, the faces' normals; beside a smooth surface, its normal
        there); their mean where they do not bracket a least distance (the reach's end)."""
        n = len(shift)
        ends = self.where_all(np.stack([shift - self.spacing, shift + self.spacing], axis=1))
        gradient = distance_gradient(distance, ends, _GRADIENT_STEP).reshape(n, 2, 3)
        before, after = gradient[:, 0], gradient[:, 1]
        k1 = np.einsum("ni,ni->n", before, self.tangents)
        k2 = np.einsum("ni,ni->n", after, self.tangents)
        bracket = (k1 < 0.0) & (k2 > 0.0)
        weight = np.divide(k2, k2 - k1, out=np.full(n, 0.5), where=bracket)
        g = weight[:, None] * before + (1.0 - weight[:, None]) * after
        g = g - np.einsum("ni,ni->n", g, self.tangents)[:, None] * self.tangents
        variance = np.einsum("ni,nij,nj->n", g, self.across, g)
        variance = variance + (shift * self.slope) ** 2 * np.einsum("ni,ni->n", g, g)
        return np.asarray(np.sqrt(np.maximum(variance, 1e-18)))

    def shifted(
        self, distance: Callable[[FloatArray], FloatArray], across: FloatArray
    ) -> FloatArray:
        """Where along each line its nearest point lies (m, shape (n,); :meth:`touching`)."""
        return self.touching(distance, across)[0]

    def touching(
        self, distance: Callable[[FloatArray], FloatArray], across: FloatArray
    ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """Where along each line its nearest point lies (m), the mean square of d's slopes
        beside it, how deep the line reaches into the shape within its reach (m, <= 0; 0
        without a tangent) and where (m), each shape (n,): the nearest point of the line moved
        out by that depth, where it touches (:meth:`nearest` of d less the depth)."""
        values = self.sampled(distance)
        least, least_shift = self.least(values, self.arc)
        depth = np.where(np.isfinite(self.along), np.minimum(least, 0.0), 0.0)
        shift, slope2 = self.nearest(distance, values - depth[:, None], across, depth)
        return shift, slope2, depth, least_shift

    def residuals(
        self, distance: Callable[[FloatArray], FloatArray], across: FloatArray
    ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]:
        """Each contact's distance d at its nearest point along its line beyond the line's
        depth (m), its standard deviation (m), the residuals of its place there and of its
        line's cut (module docstring, "Distance.", shape (n, 2)), the share of the point's
        deviation along the link that the place is measured to (0 to 1), and d there where
        negative (m, the depth the link's line residual allows), each shape (n,) unless said,
        for the deviations ``across`` (m) along the normal there (inf for a point that weighs
        nothing: its residuals are then 0)."""
        shift, slope2, depth, least_shift = self.touching(distance, across)
        reached = np.asarray(distance(self.where(shift)), dtype=float)
        at = reached - depth
        sigma = np.sqrt(across**2 + (shift * self.slope) ** 2)
        weighed = np.isfinite(across) & np.isfinite(self.along)
        place = np.divide(shift, self.along, out=np.zeros(len(shift)), where=weighed)
        cut_sigma = np.where(
            np.isfinite(self.along), self.least_sigma(distance, least_shift), across
        )
        cut = np.divide(depth, cut_sigma, out=np.zeros(len(shift)), where=np.isfinite(across))
        # the share of the point's variance along the link its place measures (the
        # information d's slope along the line gives against the point's own)
        pinned = np.where(weighed, slope2 / np.maximum(across, 1e-12) ** 2, 0.0)
        own = np.where(weighed, 1.0 / np.maximum(self.along, 1e-12) ** 2, 1.0)
        share = pinned / (pinned + own)
        return at, sigma, np.stack([place, cut], axis=1), share, np.minimum(reached, 0.0)


def _algebraic_sphere(points: FloatArray) -> tuple[FloatArray, float]:
    """Centre and radius of |p|^2 = 2 c . p + (r^2 - |c|^2) by linear least squares."""
    a = np.hstack([2.0 * points, np.ones((len(points), 1))])
    b = np.sum(points**2, axis=1)
    solution, *_ = np.linalg.lstsq(a, b, rcond=None)
    centre = solution[:3]
    radius_sq = solution[3] + centre @ centre
    return centre, float(math.sqrt(radius_sq)) if radius_sq > 0 else math.inf


def _starts(
    shape: Primitive, points: FloatArray, outward: FloatArray, rng: np.random.Generator
) -> tuple[list[FloatArray], list[FloatArray]]:
    """Initial parameter vectors for ``shape`` from the points' geometry: the first starts
    (the algebraic sphere's centre and radius; the axis along each of the points' principal
    axes, both senses for the cone; the principal frame and random rotations for the box), and
    for an axisymmetric class the further ones its points-alone fits also start from: the
    first start's shape with its axis along each of :data:`_ICOSAHEDRON_AXES` (both senses for
    a cone), and each first start with its sizes :data:`RESIZED_STARTS` times as large. A
    squat or one-sided patch gives its principal axes no clear order and its algebraic sphere
    no clear radius, and a fit from those alone can stop far from the class's best."""
    centroid = points.mean(axis=0)
    centred = points - centroid
    _, spread_sq, axes = np.linalg.svd(centred, full_matrices=False)
    spread = float(max(np.sqrt(spread_sq[0] ** 2 / len(points)) * 2.0, 1e-3))
    centre, radius = _algebraic_sphere(points)
    if not (
        math.isfinite(radius)
        and radius < 5 * spread
        and np.linalg.norm(centre - centroid) < 5 * spread
    ):
        radius = spread
        centre = centroid - outward * spread
    if shape.name == "plane":
        normal = axes[2] if axes[2] @ outward >= 0 else -axes[2]
        polar = math.acos(float(np.clip(normal[2], -1, 1)))
        azimuth = math.atan2(normal[1], normal[0])
        return [np.array([polar, azimuth, float(normal @ centroid)])], []
    if shape.name == "sphere":
        return [np.array([*centre, radius])], []
    senses = (1.0, -1.0) if shape.name == "cone" else (1.0,)
    rotations = _axis_rotations(axes, senses)
    size = max(radius, 0.5 * spread)
    if shape.name == "box":
        frame = axes.T if np.linalg.det(axes.T) > 0 else axes.T * np.array([1, 1, -1])
        rotations = [Rotation.from_matrix(frame).as_rotvec()]
        rotations += [Rotation.random(random_state=rng).as_rotvec() for _ in range(5)]
        return [_posed_start(shape.name, centre, rotvec, size) for rotvec in rotations], []
    first = [_posed_start(shape.name, centre, rotvec, size) for rotvec in rotations]
    turned = [
        _posed_start(shape.name, centre, rotvec, size)
        for rotvec in _axis_rotations(_ICOSAHEDRON_AXES, senses)
    ]
    resized = [
        _posed_start(shape.name, centre, rotvec, factor * size)
        for factor in RESIZED_STARTS
        for rotvec in rotations
    ]
    return first, turned + resized


def _axis_rotations(axes: FloatArray, senses: tuple[float, ...]) -> list[FloatArray]:
    """Rotation vectors (rad) taking Z onto each of ``axes`` (unit, shape (k, 3)) in each of
    ``senses``."""
    rotations = []
    for axis in axes:
        for sense in senses:
            rotation, _ = Rotation.align_vectors([sense * axis], [[0.0, 0.0, 1.0]])
            rotations.append(rotation.as_rotvec())
    return rotations


def _posed_start(name: str, centre: FloatArray, rotvec: FloatArray, size: float) -> FloatArray:
    """A posed class's start: about ``centre`` (m), its own Z axis turned by ``rotvec`` (rad),
    its sizes in proportion to ``size`` (m)."""
    if name == "cylinder":
        return np.array([*centre, *rotvec, size, 2 * size])
    if name == "capsule":
        return np.array([*centre, *rotvec, size, size])
    if name == "cone":  # its base half a size below the centre along its axis
        z_axis = Rotation.from_rotvec(rotvec).as_matrix()[:, 2]
        return np.array([*(centre - 0.5 * size * z_axis), *rotvec, size, 2 * size])
    if name == "torus":
        # major 0.7, minor 0.3 of the size: a hole of 0.4
        return np.array([*centre, *rotvec, 0.4 * size, 0.3 * size])
    return np.array([*centre, *rotvec, 1.5 * size, 1.5 * size, 1.5 * size])  # box


_GOLDEN = (1.0 + math.sqrt(5.0)) / 2.0

#: Six axes through opposite vertices of a regular icosahedron (unit vectors): directions
#: 63.4 deg apart that cover every axis a shape may have to within 37.4 deg, for the further
#: starts of the axisymmetric classes (:func:`_starts`).
_ICOSAHEDRON_AXES = np.array(
    [
        [0.0, 1.0, _GOLDEN],
        [0.0, -1.0, _GOLDEN],
        [1.0, _GOLDEN, 0.0],
        [-1.0, _GOLDEN, 0.0],
        [_GOLDEN, 0.0, 1.0],
        [-_GOLDEN, 0.0, 1.0],
    ]
) / math.sqrt(1.0 + _GOLDEN**2)

#: The sizes the extent prior holds at the points' span, by class: the only sizes an untouched
#: end can leave as lower bounds (a free radius drifts, and is not measured).
_PRIOR_HELD = {
    "box": ("extent_x", "extent_y", "extent_z"),
    "cylinder": ("height",),
    "capsule": ("length",),
    "cone": ("height",),
}


def _extent_prior(
    name: str, x: FloatArray, points: FloatArray, free_apex: bool = False
) -> FloatArray:
    """The extent prior's residuals (dimensionless; :data:`EXTENT_PRIOR`): how far the shape's
    extents along its own axes exceed the points' span there over that scale, for the classes
    of :data:`_PRIOR_HELD`; with ``free_apex`` a cone's base side only."""
    if name not in _PRIOR_HELD:
        return np.zeros(0)
    local = local_coordinates(x, points)
    if name == "cone" and free_apex:
        return np.array([max(float(local[:, 2].min()), 0.0) / EXTENT_PRIOR])
    span = local.max(axis=0) - local.min(axis=0)
    if name == "box":
        return np.asarray(np.maximum(x[6:9] - span, 0.0)) / EXTENT_PRIOR
    if name == "capsule":
        extent = x[7] + 2 * x[6]
    else:  # cylinder, cone: the height
        extent = x[7]
    return np.asarray([max(extent - span[2], 0.0) / EXTENT_PRIOR])


#: A point farther from the points' median than this many times their median distance from it
#: lies apart from the rest: the fits also start from the rest's geometry (:func:`_gathered`).
GATHERED_DISTANCES = 4.0


def _gathered(points: FloatArray) -> NDArray[np.bool_]:
    """Which ``points`` (m, shape (n, 3)) lie with the rest: within :data:`GATHERED_DISTANCES`
    times the median distance from the coordinate-wise median (a compact object's points lie
    within about twice it, those along one outline within twice it too)."""
    distance = np.linalg.norm(points - np.median(points, axis=0), axis=1)
    return np.asarray(distance <= GATHERED_DISTANCES * np.median(distance))


def _spread(points: FloatArray) -> float:
    """The points' bounding box diagonal (m)."""
    return float(np.linalg.norm(points.max(axis=0) - points.min(axis=0)))


def outlier_cap(sigma: FloatArray, spread: float) -> FloatArray:
    """T = 2 ln((1 - eps) L / (eps sqrt(2 pi) sigma)) (module docstring), shape (n,), for the
    standard deviations ``sigma`` (m) and the points' spread L (m): beyond it a point is more
    likely wrong than right."""
    eps = OUTLIER_FRACTION
    sigma = np.maximum(np.asarray(sigma, dtype=float), 1e-12)
    cap = 2.0 * np.log((1.0 - eps) * max(spread, 1e-12) / (eps * math.sqrt(2.0 * math.pi) * sigma))
    return np.asarray(np.maximum(cap, 0.0))


def point_chi2(z2: FloatArray, sigma: FloatArray, spread: float) -> FloatArray:
    """Each point's part of chi^2 (module docstring), shape (n,): -2 ln((exp(-z^2 / 2) + e) /
    (1 + e)), e = exp(-T / 2) with T :func:`outlier_cap`, for the squared normalised residuals
    ``z2``, the standard deviations ``sigma`` (m) and the spread L (m)."""
    cap = outlier_cap(sigma, spread)
    inlier = np.logaddexp(-0.5 * np.asarray(z2, dtype=float), -0.5 * cap)
    return np.asarray(-2.0 * (inlier - np.logaddexp(0.0, -0.5 * cap)))


def _z2(
    distance: FloatArray, sigma: FloatArray, line: FloatArray, extra: FloatArray | None = None
) -> FloatArray:
    """z^2 = (d / sigma)^2 + a^2 + c^2 + r^2 per point (module docstring), shape (n,): the
    distance d (m) in its standard deviations sigma (m), the place a and cut c along the line
    (``extra``, shape (n, 2); none: None) and the link's line residual r (none: empty)."""
    z2 = (np.asarray(distance, dtype=float) / sigma) ** 2
    if extra is not None:
        z2 = z2 + np.sum(np.asarray(extra, dtype=float).reshape(len(z2), -1) ** 2, axis=1)
    return np.asarray(z2 + np.asarray(line, dtype=float) ** 2 if len(line) else z2)


def _bounds(shape: Primitive, points: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Sizes from :data:`MIN_SIZE` to :data:`MAX_SIZE_SPREADS` times the points' spread (the
    torus's hole, R - r, to one spread)."""
    n = len(shape.parameter_names)
    low = np.full(n, -np.inf)
    high = np.full(n, np.inf)
    n_sizes = {"plane": 0, "sphere": 1, "box": 3}.get(shape.name, 2)
    spread = _spread(points)
    if n_sizes:
        low[n - n_sizes :] = MIN_SIZE
        high[n - n_sizes :] = max(MAX_SIZE_SPREADS * spread, 10 * MIN_SIZE)
    if shape.name == "torus":
        # a ring whose hole is wider than all the touches is a bent cylinder, one parameter
        # dearer: the torus is the class of rings the points go around
        high[6] = max(spread, 10 * MIN_SIZE)
    return low, high


def fit_primitive(
    shape: Primitive | str,
    points: ArrayLike,
    covariances: ArrayLike,
    outward: ArrayLike | None = None,
    rng: np.random.Generator | None = None,
    lines: LinkLines | None = None,
    swept: Sequence[FreeSpace] = (),
) -> ClassFit:
    """Fit one class to the points (module docstring).

    Parameters
    ----------
    shape : Primitive or str
        The class.
    points : array, shape (n, 3)
        World points (m).
    covariances : array, shape (n, 3, 3)
        Their covariances (m^2).
    outward : array, shape (3,), optional
        A direction from the object towards where the antenna came from (unit), to start the
        fits on the right side; the mean direction to the centroid's opposite when None.
    rng : numpy.random.Generator, optional
        For the extra starting rotations of the box (seeded default).
    lines : LinkLines, optional
        The link's line at each contact: a tangency residual per contact (module docstring).
    swept : sequence of FreeSpace
        Where links swept untouched (:class:`FreeSpace`) and where they touched
        (:class:`~sensing_antenna.mapping.free_space.Touches`): a residual per sweep or contact
        (module docstring).
    """
    model = PRIMITIVES[shape] if isinstance(shape, str) else shape
    p = np.asarray(points, dtype=float).reshape(-1, 3)
    cov = np.asarray(covariances, dtype=float).reshape(-1, 3, 3)
    direction = _outward(p, outward)
    generator = rng if rng is not None else np.random.default_rng(0)
    low, high = _bounds(model, p)
    sigma = _isotropic_sigma(cov)
    spread = _spread(p)
    touch = _Touch.of(p, cov, lines)

    placed = lines.placed(p) if lines is not None else None
    spaces = [space.near(p, FREE_MARGIN + 0.5 * spread) for space in swept]
    link_evidence = lines is not None or bool(spaces)

    # The residuals of the fits (line, swept, touched, point and residuals below) take one
    # parameter vector x, shape (k,), or a batch of them, shape (B, k) (a finite-difference
    # Jacobian's columns in one call): the contacts' quantities come back flat, shape (B * n,),
    # block by block; the residual vectors, shape (B, m). The scores' helpers take one x.
    @functools.cache
    def tiled(copies: int) -> tuple[_Touch, PlacedLines | None]:
        return touch.tiled(copies), None if placed is None else placed.tiled(copies)

    def distance_of(x: FloatArray) -> Callable[[FloatArray], FloatArray]:
        # d at query points built contact by contact from the tiled lines: block b is x[b]'s
        if x.ndim == 1:
            return functools.partial(model.signed_distance, x)
        return lambda q: model.signed_distance(x, q.reshape(len(x), -1, 3)).reshape(-1)

    def distance_at(x: FloatArray, q: FloatArray) -> FloatArray:
        # d of each vector of x at the same points q (m, shape (k, 3)): shape (k,) or (B, k)
        return model.signed_distance(x, np.broadcast_to(q, (*x.shape[:-1], *q.shape)))

    def copies(x: FloatArray) -> int:
        return 1 if x.ndim == 1 else len(x)

    def rows(x: FloatArray, parts: Sequence[FloatArray]) -> FloatArray:
        # flat parts, block by block, joined into each vector's residuals
        joined = np.concatenate([np.reshape(part, (copies(x), -1)) for part in parts], axis=1)
        return joined[0] if x.ndim == 1 else joined

    def line_residuals(
        x: FloatArray, s: FloatArray, touched: FloatArray, search: bool = True
    ) -> FloatArray:
        # beyond the nearest point's reach, when it was searched for
        touch_x, lines_x = tiled(copies(x))
        if lines_x is None:
            return np.zeros(0)
        sigma_x = np.tile(s, copies(x))
        if not search:
            return lines_x.residuals(distance_of(x), sigma_x, touched)
        return lines_x.residuals(distance_of(x), sigma_x, touched, touch_x.reach, touch_x.across)

    def swept_residuals(x: FloatArray, regions: Sequence[FreeSpace]) -> FloatArray:
        return _swept_residuals(regions, functools.partial(distance_at, x), x.shape[:-1])

    def touched(
        x: FloatArray, s: FloatArray
    ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]:
        # each contact at its nearest point along its line: distance beyond the line's depth
        # (m), deviation (m), place and cut (in deviations), the share of its deviation along
        # the link measured, and the depth its link's line residual allows (m)
        return tiled(copies(x))[0].residuals(distance_of(x), np.tile(s, copies(x)))

    def normal_sigma(x: FloatArray) -> FloatArray:
        # the deviation across the link along the shape's normal at each contact's nearest
        # point along its line (found with the normal at the point itself)
        first = touch.across_sigma(model.normals(x, p))
        shift = touch.shifted(lambda q: model.signed_distance(x, q), first)
        return touch.across_sigma(model.normals(x, touch.where(shift)))

    def point_residuals(x: FloatArray, s: FloatArray, with_lines: bool) -> FloatArray:
        # d_i / sigma_i at the nearest points along the lines, their places and cuts, and the
        # lines' residuals
        at, sigma_at, extra, _, reached = touched(x, s)
        line = line_residuals(x, s, reached) if with_lines else np.zeros(0)
        return rows(x, [at / sigma_at, extra[:, 0], extra[:, 1], line])

    def residuals(
        x: FloatArray,
        s: FloatArray,
        with_lines: bool,
        regions: Sequence[FreeSpace],
        free_apex: bool = False,
        search: bool = True,
    ) -> FloatArray:
        if search:
            points_part = point_residuals(x, s, with_lines)
        else:  # the Euclidean d_i / sigma_i
            distance = distance_at(x, p).reshape(-1)
            line = line_residuals(x, s, distance, search=False) if with_lines else np.zeros(0)
            points_part = rows(x, [distance / np.tile(s, copies(x)), line])
        # the span of the points the fit takes (those left out, inf, may lie far away)
        taken = p[np.isfinite(s)] if np.any(np.isfinite(s)) else p
        prior = np.reshape(
            [
                _extent_prior(model.name, v, taken, free_apex)
                for v in np.reshape(x, (copies(x), -1))
            ],
            (copies(x), -1),
        )
        return rows(x, [points_part, swept_residuals(x, regions), prior])

    def fit(
        start: FloatArray,
        s: FloatArray,
        with_lines: bool,
        evaluations: int,
        regions: Sequence[FreeSpace] = (),
        free_apex: bool = False,
        search: bool = True,
    ) -> Any:
        arguments = (s, with_lines, regions, free_apex, search)

        def columns(_: Any, steps: Any) -> list[FloatArray]:
            # the finite-difference Jacobian's evaluations (scipy's own steps) in one batch:
            # least_squares hands ``workers`` its residual function and those steps, and uses
            # it for nothing else, so the function handed (that of ``residuals``) is not called
            return list(residuals(np.array(list(steps)), *arguments))

        return least_squares(
            residuals,
            start,
            args=arguments,
            bounds=(low, high),
            loss="soft_l1",
            f_scale=ROBUST_SCALE,
            max_nfev=evaluations * len(start),
            workers=columns,
            xtol=FIT_TOLERANCE,
            ftol=FIT_TOLERANCE,
        )

    def point_z2(x: FloatArray, s: FloatArray) -> FloatArray:
        at, sigma_at, extra, _, reached = touched(x, s)
        return _z2(at, sigma_at, line_residuals(x, s, reached), extra)

    def inlier_sigma(x: FloatArray, s: FloatArray) -> FloatArray:
        # a point the mixture counts as wrong at x (its z^2 beyond its cap) weighs nothing
        wrong = point_z2(x, s) > outlier_cap(s, spread)
        return np.where(wrong, np.inf, s)

    def refine(
        x: FloatArray,
        free_apex: bool = False,
        exclude: bool = True,
        leave_out: NDArray[np.bool_] | None = None,
    ) -> FloatArray:
        # each point's sigma across the link along the fitted surface's normal at its nearest
        # point, and the link's lines; with ``exclude`` the points counted wrong leave the
        # refinement, and those of ``leave_out``; free-space samples far outside the shape at
        # x do
        sigma_x = normal_sigma(x)
        kept = inlier_sigma(x, sigma_x) if exclude else sigma_x
        if leave_out is not None:
            kept = np.where(leave_out, np.inf, kept)
        regions = [
            space.within(model.signed_distance(x, space.samples), FREE_ACTIVE) for space in spaces
        ]
        evaluations = 2 * MAX_EVALUATIONS
        solution = fit(x, kept, lines is not None, evaluations, regions, free_apex)
        return np.asarray(solution.x)

    def total(x: FloatArray) -> float:
        # the scored chi^2 (plus the extent prior) with the sigma at x: one scale for all
        sigma_x = normal_sigma(x)
        parts = point_chi2(point_z2(x, sigma_x), sigma_x, spread)
        free_parts = _swept_chi2(swept_residuals(x, spaces), spaces, spread)
        kept = np.isfinite(inlier_sigma(x, sigma_x))
        prior = _extent_prior(model.name, x, p[kept] if np.any(kept) else p)
        return float(np.sum(parts) + np.sum(free_parts) + np.sum(prior**2))

    # each start fitted on the points alone (a smooth problem); with lines, also from each
    # first start with them, and the best few of the points-alone fits refined: the lines make the
    # problem rough, and either path may be the one that finds the shape
    alone, direct = [], []
    first, further = _starts(model, p, direction, generator)
    for index, start in enumerate(first + further):
        start = np.clip(start, low, high)
        try:
            alone.append(fit(start, sigma, False, MAX_EVALUATIONS, search=False))
            if lines is not None and index < len(first):
                direct.append(fit(start, sigma, True, MAX_EVALUATIONS, search=False).x)
        except ValueError:  # a start outside the model's domain
            continue
    assert alone
    alone.sort(key=lambda solution: solution.cost)
    chosen = alone[: REFINED_STARTS if link_evidence else 1]
    # each refined twice: a start the Euclidean distances grew past edges counts the points
    # there wrong, and the second refinement, from the first's shape, takes them back
    starts = [solution.x for solution in chosen] + direct
    candidates = [refine(refine(start, exclude=False)) for start in starts]
    # a point far from the rest (a misplaced base pose) moves every start made of all the
    # points; the starts of the rest, fitted without it, give the fits that count it wrong
    kept = _gathered(p)
    if not np.all(kept):
        apart = np.where(kept, sigma, np.inf)
        trimmed = []
        for start in _starts(model, p[kept], direction, generator)[0]:
            try:
                start = np.clip(start, low, high)
                trimmed.append(fit(start, apart, False, MAX_EVALUATIONS, search=False))
            except ValueError:
                continue
        trimmed.sort(key=lambda solution: solution.cost)
        candidates += [
            refine(refine(s.x, exclude=False, leave_out=~kept))
            for s in trimmed[: REFINED_STARTS if link_evidence else 1]
        ]
    x = model.canonical(min(candidates, key=total) if len(candidates) > 1 else candidates[0])
    distance = model.signed_distance(x, p)
    sigma = normal_sigma(x)
    touches = touched(x, sigma)

    def uncertainty(
        v: FloatArray,
    ) -> tuple[FloatArray, FloatArray, FloatArray, tuple[FloatArray, ...]]:
        # the covariance, the sizes' deviations and lower-bound margins at v (size_std), from
        # the evidence alone: without the extent prior, the points counted wrong at v left out
        kept = inlier_sigma(v, normal_sigma(v))

        def evidence(u: FloatArray) -> FloatArray:
            return np.concatenate(
                [
                    point_residuals(u, kept, True),
                    swept_residuals(u, spaces),
                ]
            )

        covariance = parameter_covariance(v, evidence, spread)
        return (covariance, *size_std(model, v, covariance, evidence, spread, kept))

    shaped, measured = x, None
    if model.name == "cone":
        # a cone's apex let go from the points' reach to where its slant places it, kept when
        # the evidence measures every size of that shape, or bounds it from below (module
        # docstring, "Sizes.")
        refit = model.canonical(refine(x, free_apex=True))
        measured = uncertainty(refit)
        if np.any(np.isinf(measured[1]) & np.isnan(measured[2])):
            measured = None
        else:
            shaped = refit
    covariance, std, margin, free = measured if measured is not None else uncertainty(x)

    fitted = _scored(
        model.name,
        dict(zip(model.parameter_names, x.tolist(), strict=True)),
        dict(zip(model.size_names, model.sizes(x).tolist(), strict=True)),
        distance,
        sigma,
        model.dof,
        vector=x,
        mesh=model.mesh(x),
        spread=spread,
        line=line_residuals(x, sigma, touches[4]),
        swept=swept_residuals(x, spaces),
        spaces=spaces,
        touches=touches[:4],
    )
    at_least = np.maximum(model.sizes(shaped) - margin, 0.0)
    return dataclasses.replace(
        fitted,
        parameters=dict(zip(model.parameter_names, shaped.tolist(), strict=True)),
        sizes=dict(zip(model.size_names, model.sizes(shaped).tolist(), strict=True)),
        vector=shaped,
        mesh=model.mesh(shaped),
        covariance=covariance,
        free_ends=free,
        size_std=dict(zip(model.size_names, std.tolist(), strict=True)),
        size_at_least={
            n: float(at_least[i]) for i, n in enumerate(model.size_names) if np.isfinite(margin[i])
        },
    )


def _gradient(function: Callable[[FloatArray], FloatArray], x: FloatArray) -> FloatArray:
    """d function / d x at ``x`` by central differences of :data:`JACOBIAN_STEP`, shape
    (len(function(x)), len(x))."""
    columns = []
    for j in range(len(x)):
        shift = np.zeros(len(x))
        shift[j] = JACOBIAN_STEP
        columns.append((function(x + shift) - function(x - shift)) / (2 * JACOBIAN_STEP))
    return np.stack(columns, axis=1)


def _carried(
    function: Callable[[FloatArray], FloatArray], x: FloatArray, covariance: FloatArray
) -> FloatArray:
    """Standard deviation of each of ``function``'s values at ``x`` under the parameters'
    ``covariance``, to first order (g^T C g, g its :func:`_gradient`), shape
    (len(function(x)),)."""
    gradient = _gradient(function, x)
    variance = np.einsum("ij,jk,ik->i", gradient, covariance, gradient)
    return np.asarray(np.sqrt(np.maximum(variance, 0.0)))


def parameter_covariance(
    x: FloatArray, residuals: Callable[[FloatArray], FloatArray], reach: float = math.inf
) -> FloatArray:
    """The covariance of the parameters at ``x``, shape (n, n) (units of the parameters
    squared), from the normalised ``residuals``: first Gauss-Newton's (J^T J)^-1, J the
    Jacobian by central differences of :data:`JACOBIAN_STEP`, each eigenvalue of J^T J floored
    at :data:`EIGEN_FLOOR` of the largest (a direction the residuals do not hold gets a variance
    far beyond any size; inf throughout when they hold none, NaN when J^T J is not finite).
    Then the residuals' slopes are measured again along each principal axis whose deviation
    is within ``reach`` (m or rad; the others are kept), forward and back over one deviation,
    and the information is their mean square, :data:`SECANT_ROUNDS` times, each round's steps
    the geometric mean of the last round's and the deviations it gave: the residuals are
    piecewise smooth (a contact's nearest point moves from one face to the next, a line's cut
    starts), a fit often stops where their slopes change, and the slopes there can be far
    steeper than over the range the parameters are uncertain by."""
    n = len(x)
    jacobian = _gradient(residuals, x)
    information = jacobian.T @ jacobian
    if not np.all(np.isfinite(information)):
        return np.full((n, n), np.nan)
    eigenvalues, eigenvectors = np.linalg.eigh(information)
    floor = EIGEN_FLOOR * float(eigenvalues[-1])
    if not floor > 1.0 / np.finfo(float).max:
        return np.full((n, n), np.inf)  # the residuals hold no direction
    held = int(np.sum(eigenvalues > floor))
    covariance = (eigenvectors / np.maximum(eigenvalues, floor)) @ eigenvectors.T
    # the held axes within reach (the covariance's smallest), measured again; the others kept
    variances, axes = np.linalg.eigh(covariance)
    deviations = np.sqrt(np.maximum(variances, 0.0))
    measured = int(np.sum(deviations[:held] <= reach))
    if measured == 0:
        return np.asarray(covariance)
    basis, steps = axes[:, :measured], deviations[:measured]
    at_x = residuals(x)
    inverse = np.diag(variances[:measured])
    for _ in range(SECANT_ROUNDS):
        information = np.zeros((measured, measured))
        for sign in (1.0, -1.0):
            slopes = np.stack(
                [
                    (residuals(x + sign * h * basis[:, j]) - at_x) / (sign * h)
                    for j, h in enumerate(steps)
                ],
                axis=1,
            )
            if not np.all(np.isfinite(slopes)):
                return np.asarray(covariance)
            information += 0.5 * slopes.T @ slopes
        values, vectors = np.linalg.eigh(information)
        inverse = (vectors / np.maximum(values, floor)) @ vectors.T
        # the next round's steps: the geometric mean of these and the deviations they gave
        # (undamped, a residual that curves would swing them between two scales)
        steps = np.minimum(np.sqrt(steps * np.sqrt(np.diag(inverse))), reach)
    free = axes[:, measured:]
    return np.asarray(basis @ inverse @ basis.T + (free * variances[measured:]) @ free.T)


def size_std(
    shape: Primitive,
    x: FloatArray,
    covariance: FloatArray,
    residuals: Callable[[FloatArray], FloatArray],
    spread: float,
    point_std: FloatArray,
) -> tuple[FloatArray, FloatArray, tuple[FloatArray, ...]]:
    """Standard deviation (m) of each of ``shape``'s sizes at the fit ``x``, shape (n_sizes,),
    for a size that is only a lower bound how far below the fitted size the bound lies (m;
    NaN for the others), and the free ends (below): the parameter vector's change per metre
    each grows by.

    The parameters' ``covariance`` (:func:`parameter_covariance` of ``residuals``, a function of
    the parameter vector whose first len(``point_std``) entries are the points' d_i / sigma_i, at
    their nearest points along their lines)
    carried to the sizes; inf (not measured) where a size moves along a direction the residuals
    do not hold (its deviation then exceeds the points' spread ``spread``, m) or the covariance
    is not finite (NaN throughout: nothing else is judged). ``point_std`` are the points'
    deviations along the normal (m, inf for a point left out). Then each end
    (:meth:`Primitive.growths`) is grown by D and by 2 D, D = max(2 sigma, 3 times a deviation
    of the points whose distance moves with that end), sigma the largest finite deviation the
    covariance gives the sizes it moves: a fit held at the smallest size the points allow has an
    untouched end at the outermost points, where the distance's derivative differs on either
    side, and growing it first releases the points within their noise of it, after which only
    what holds the end resists, as the square of the distance. A rise of the residuals' sum of
    squares below 1 from D to 2 D leaves the end free: the sizes it moves have no deviation, and
    those the extent prior holds (a box's extents, a cylinder's height, a capsule's length, a
    cone's height) are lower bounds, three times the largest deviation of the points at that end
    (at least the median point's) below the fitted size. Each end is grown at two scales, D from
    the median and from the largest deviation of its points (a few wide points may be all that
    hold it), and is held when either resists. Otherwise the rise, 3 D^2 / s^2, gives the end's
    own deviation s, and each measured size it moves has a deviation of at least s times the
    rate it moves at.
    """
    if np.all(np.isnan(covariance)):
        nothing = np.full(len(shape.size_names), np.nan)
        return np.full(len(shape.size_names), np.inf), nothing, ()
    at_x = residuals(x)
    free: list[FloatArray] = []
    std = np.full(len(shape.size_names), np.inf)
    if np.all(np.isfinite(covariance)):
        deviation = _carried(shape.sizes, x, covariance)
        std = np.where(deviation <= spread, deviation, np.inf)
    carried = std.copy()  # each end's step from the covariance's deviations, not another end's
    kept = np.isfinite(point_std)  # every point counted wrong: none
    typical = float(np.median(point_std[kept])) if np.any(kept) else 0.0
    held_by_prior = [name in _PRIOR_HELD.get(shape.name, ()) for name in shape.size_names]
    margin = np.full(len(shape.size_names), np.nan)
    for sizes, change in shape.growths(x):
        # the points whose distance moves with this end (at least half as fast), and the step
        # from their deviations: near the end, before any of them meets another face
        moved = residuals(x + JACOBIAN_STEP * change)[: len(point_std)] - at_x[: len(point_std)]
        attached = kept & (np.abs(moved) * np.where(kept, point_std, 0.0) > 0.5 * JACOBIAN_STEP)
        widths = point_std[attached] if np.any(attached) else np.array([typical])
        finite = carried[list(sizes)][np.isfinite(carried[list(sizes)])]
        least = 2.0 * float(finite.max()) if finite.size else 0.0
        # at two scales: the typical attached point's, and the widest's (a few wide points may
        # be all that hold an end); held when either resists
        rise, step = 0.0, 0.0
        for width in sorted({float(np.median(widths)), float(np.max(widths))}):
            d = max(least, 3.0 * width)
            if not d > 0.0:
                continue
            near, far = (float(np.sum(residuals(x + k * d * change) ** 2)) for k in (1.0, 2.0))
            if far - near >= max(rise, 1.0) or not step:
                rise, step = far - near, d
        if not step > 0.0:
            continue
        noise = float(np.max(widths))
        rates = np.abs(shape.sizes(x + change) - shape.sizes(x))  # per metre of growth
        if rise < 1.0:
            free.append(np.asarray(change, dtype=float))
        for index in sizes:
            if rise < 1.0:
                # a free end: a size the prior held at the outermost points is a lower bound,
                # three of their largest deviation below it; any other is not measured
                std[index] = np.inf
                if held_by_prior[index]:
                    margin[index] = max(np.nan_to_num(margin[index]), 3.0 * max(noise, typical))
            elif math.isfinite(std[index]):
                # the end's own deviation, carried to this size (a cone's radius moves by R / h)
                std[index] = max(std[index], rates[index] * step * math.sqrt(3.0 / rise))
    return np.asarray(std), margin, tuple(free)


def fit_mesh(
    name: str,
    mesh: trimesh.Trimesh,
    points: ArrayLike,
    covariances: ArrayLike,
    rng: np.random.Generator | None = None,
    n_starts: int = 24,
    lines: LinkLines | None = None,
    swept: Sequence[FreeSpace] = (),
) -> ClassFit:
    """Register a user mesh (its own size, any pose) to the points by ICP and score it.

    The points are moved onto the mesh (trimesh.registration.icp, the closest point on the
    mesh for each point: right for points covering only part of the object) from ``n_starts``
    rotations about the points' centroid placed on the mesh's centre and from the alignment of
    principal axes (trimesh.registration.mesh_other), each on at most :data:`START_POINTS` of
    the points for up to 40 iterations until its cost changes by less than
    :data:`ICP_TOLERANCE` of their variance; the lowest is refined to convergence on all
    points. With ``lines`` and a closed mesh, the :data:`MESH_CANDIDATES` lowest distinct
    starts are refined and the one whose points and lines give the lowest chi^2 kept, slid
    along the directions the points leave free when its lines cross the mesh (:func:`_slid`).
    ``lines`` adds
    the tangency residuals of the registered mesh and ``swept`` its swept links' residuals (not
    used to register it), for a closed (watertight) mesh only: an open one has no inside.
    """
    p = np.asarray(points, dtype=float).reshape(-1, 3)
    cov = np.asarray(covariances, dtype=float).reshape(-1, 3, 3)
    generator = rng if rng is not None else np.random.default_rng(0)
    rotations = [np.eye(3)] + [
        Rotation.random(random_state=generator).as_matrix() for _ in range(n_starts - 1)
    ]
    centroid = p.mean(axis=0)
    target = mesh.bounding_box.centroid
    initials = []
    for rotation in rotations:
        initial = np.eye(4)
        initial[:3, :3] = rotation
        initial[:3, 3] = target - rotation @ centroid
        initials.append(initial)
    # and the principal axes' alignment (trimesh.registration.mesh_other), inverted
    mesh_to_points, _ = trimesh.registration.mesh_other(
        mesh,
        p,
        samples=300,
        scale=False,
        icp_first=5,
        icp_final=20,
        reflection=False,
        seed=int(generator.integers(2**31)),
    )
    initials.append(np.linalg.inv(mesh_to_points))
    # each start until its mean squared distance (m^2) changes by less than ICP_TOLERANCE of the
    # points' variance: trimesh's default, 1e-5 m^2, ten times a 1 mm variance, stopped every
    # start within an iteration or two, where the lowest need not end lowest
    variance = float(np.mean(np.trace(cov, axis1=1, axis2=2)) / 3.0)
    # the starts on at most START_POINTS of the points, spread over them (a start's basin is the
    # shape's; the refinement below uses them all)
    sample = p[np.linspace(0, len(p) - 1, min(len(p), START_POINTS)).round().astype(int)]
    started = []
    for initial in initials:
        matrix, _, cost = trimesh.registration.icp(
            sample,
            mesh,
            initial=initial,
            max_iterations=40,
            threshold=ICP_TOLERANCE * variance,
            reflection=False,
            scale=False,
        )
        started.append((float(cost), np.asarray(matrix)))
    # the best start refined to convergence; with the links' lines (a closed mesh), of the best
    # MESH_CANDIDATES distinct starts the pose the points and lines fit best: few points fit
    # several poses, some of which put the mesh where a link passed
    started.sort(key=lambda start: start[0])
    evidence = mesh.is_watertight and lines is not None
    starts = _distinct_poses([m for _, m in started], centroid, MESH_CANDIDATES if evidence else 1)
    refined = []
    for start in starts:
        points_to_mesh, _, _ = trimesh.registration.icp(
            p,
            mesh,
            initial=start,
            max_iterations=300,
            threshold=1e-10,
            reflection=False,
            scale=False,
        )
        refined.append(points_to_mesh)
    if len(refined) == 1:
        return _registered(name, mesh, p, cov, refined[0], lines, swept)
    # ranked on the points and the lines; the swept links, costly to place, are scored for the
    # best alone
    ranked = [_registered(name, mesh, p, cov, m, lines, ()) for m in refined]
    k = min(range(len(ranked)), key=lambda i: ranked[i].chi2)
    best, fitted = _slid(name, mesh, p, cov, refined[k], lines, ranked[k])
    return _registered(name, mesh, p, cov, best, lines, swept) if swept else fitted


def _slid(
    name: str,
    mesh: trimesh.Trimesh,
    p: FloatArray,
    cov: FloatArray,
    points_to_mesh: FloatArray,
    lines: LinkLines | None,
    fitted: ClassFit,
) -> tuple[FloatArray, ClassFit]:
    """``points_to_mesh`` (4 x 4) and its fit ``fitted``, or, when the links' ``lines`` cross
    the registered mesh, the pose slid along each direction the points leave free
    (:data:`FREE_SHARE`) to where the points and the lines fit best: ICP moves a mesh only as
    far as its points' distances ask, and points on a cylinder's side leave it anywhere along
    its axis, where the links that passed beyond its end may cross it. Tried at
    :data:`FREE_SHIFTS` shifts over the mesh's largest extent, the best refined between its
    neighbours."""
    if lines is None or not fitted.line_chi2 > 1.0:
        return points_to_mesh, fitted
    q = trimesh.transform_points(p, points_to_mesh)
    _, _, faces = closest_point(mesh, q)
    normals = np.asarray(mesh.face_normals[faces])
    world = normals @ np.linalg.inv(points_to_mesh)[:3, :3].T
    weighted = normals / _normal_sigma(cov, world)[:, None]
    _, singular, directions = np.linalg.svd(weighted, full_matrices=False)
    free = directions[singular <= FREE_SHARE * singular[0]]
    reach = 0.5 * float(np.max(mesh.extents))
    best, kept = points_to_mesh, fitted
    for direction in free:
        tried: dict[float, tuple[FloatArray, ClassFit]] = {}  # each shift's pose and fit, once

        def chi2(
            shift: float,
            start: FloatArray = best,
            v: FloatArray = direction,
            tried: dict[float, tuple[FloatArray, ClassFit]] = tried,
        ) -> float:
            if shift not in tried:
                step = np.eye(4)
                step[:3, 3] = shift * v
                pose = step @ start
                tried[shift] = (pose, _registered(name, mesh, p, cov, pose, lines, ()))
            return tried[shift][1].chi2

        shifts = np.linspace(-reach, reach, FREE_SHIFTS)
        i = int(np.argmin([chi2(float(shift)) for shift in shifts]))
        gap = shifts[1] - shifts[0]
        bounds = (shifts[i] - gap, shifts[i] + gap)
        minimize_scalar(chi2, bounds=bounds, method="bounded", options={"maxiter": 8})
        pose, trial = min(tried.values(), key=lambda tried_fit: tried_fit[1].chi2)
        if trial.chi2 < kept.chi2:
            best, kept = pose, trial
    return best, kept


def _distinct_poses(
    matrices: Sequence[FloatArray], centroid: FloatArray, most: int
) -> list[FloatArray]:
    """The first ``most`` of ``matrices`` (4 x 4, points to mesh, in order) that each place the
    points' ``centroid`` (m) more than a millimetre, or turn them by more than a hundredth of a
    radian, away from where those kept before do."""
    kept: list[FloatArray] = []
    at = np.append(centroid, 1.0)
    for matrix in matrices:
        if len(kept) == most:
            break
        if all(
            np.linalg.norm((matrix - other)[:3] @ at) > 1e-3
            or np.linalg.norm(Rotation.from_matrix(matrix[:3, :3] @ other[:3, :3].T).as_rotvec())
            > 1e-2
            for other in kept
        ):
            kept.append(matrix)
    return kept


def _registered(
    name: str,
    mesh: trimesh.Trimesh,
    p: FloatArray,
    cov: FloatArray,
    points_to_mesh: FloatArray,
    lines: LinkLines | None,
    swept: Sequence[FreeSpace],
) -> ClassFit:
    """The user mesh ``mesh`` registered by ``points_to_mesh`` (4 x 4, world to mesh) scored on
    the points ``p`` (m, (n, 3)) with covariances ``cov`` (m^2, (n, 3, 3)), the links'
    ``lines`` and the ``swept`` links (:func:`fit_mesh`)."""
    _, distance, faces = closest_point(mesh, trimesh.transform_points(p, points_to_mesh))
    pose = np.linalg.inv(points_to_mesh)  # mesh to world
    normals = mesh.face_normals[faces] @ pose[:3, :3].T
    sigma = _normal_sigma(cov, normals)
    placed = mesh.copy()
    placed.apply_transform(pose)
    parameters = {f"m{i}{j}": float(pose[i, j]) for i in range(3) for j in range(4)}
    extents = mesh.bounding_box.extents
    sizes = {f"extent_{a}": float(e) for a, e in zip("xyz", extents, strict=True)}
    line = np.zeros(0)
    sweeps, spaces = np.zeros(0), []
    touches = None
    if placed.is_watertight:
        # trimesh's signed distance is positive inside (and meaningful for a closed mesh only)
        def signed(q: FloatArray) -> FloatArray:
            return signed_distance(placed, q)

        def normals_at(q: FloatArray) -> FloatArray:
            _, _, closest = closest_point(placed, q)
            return np.asarray(placed.face_normals[closest])

        if lines is not None:
            # each contact at its nearest point along its line, as for a primitive
            touch = _Touch.of(p, cov, lines)
            shift = touch.shifted(signed, touch.across_sigma(normals))
            sigma = touch.across_sigma(normals_at(touch.where(shift)))
            at, sigma_at, extra, share, reached = touch.residuals(signed, sigma)
            touches = (at, sigma_at, extra, share)
            line = lines.placed(p).residuals(signed, sigma, reached, touch.reach, touch.across)
        # only samples within the placed mesh's box grown by this can come near it
        reach = FREE_MARGIN + 0.5 * _spread(p)
        spaces = [space.near(placed.bounds, reach) for space in swept]
        sweeps = _swept_residuals(spaces, signed)
    return _scored(
        f"mesh:{name}",
        parameters,
        sizes,
        np.asarray(distance),
        sigma,
        6,
        np.asarray(pose, dtype=float).ravel(),
        placed,
        _spread(p),
        line,
        sweeps,
        spaces,
        touches,
    )


def _scored(
    name: str,
    parameters: dict[str, float],
    sizes: dict[str, float],
    distance: FloatArray,
    sigma: FloatArray,
    dof: int,
    vector: FloatArray,
    mesh: trimesh.Trimesh | None,
    spread: float,
    line: FloatArray | None = None,
    swept: FloatArray | None = None,
    spaces: Sequence[FreeSpace] = (),
    touches: tuple[FloatArray, FloatArray, FloatArray, FloatArray] | None = None,
) -> ClassFit:
    """The fit scored; ``distance`` the points' Euclidean distances (m, for the RMS) and
    ``touches`` the lines' touches (the first four of :meth:`_Touch.residuals`), the
    Euclidean distances in ``sigma`` alone when None."""
    n = len(distance)
    lines = line if line is not None and len(line) == n else np.zeros(n)
    sweeps = swept if swept is not None else np.zeros(0)
    if touches is None:
        at, sigma_at, extra, share = distance, sigma, None, np.zeros(n)
    else:
        at, sigma_at, extra, share = touches
    # each point's and each sweep's part of chi^2; BIC = chi^2 + k ln n
    z2 = _z2(at, sigma_at, lines, extra)
    wrong = z2 > outlier_cap(sigma, spread)
    parts = point_chi2(z2, sigma, spread)
    crossed = sweeps**2 > outlier_cap(_sweep_sigma(spaces), spread) if len(sweeps) else sweeps > 0
    chi2 = float(np.sum(parts) + np.sum(_swept_chi2(sweeps, spaces, spread)))
    line_chi2 = float(np.sum(lines**2))
    return ClassFit(
        name=name,
        parameters=parameters,
        sizes=sizes,
        # over the points it takes: one far point counted wrong says nothing of the shape
        rms=float(np.sqrt(np.mean(distance[~wrong] ** 2 if np.any(~wrong) else distance**2))),
        chi2=chi2,
        line_chi2=line_chi2,
        swept_chi2=float(np.sum(sweeps**2)),
        bic=chi2 + dof * math.log(n),
        dof=dof,
        n_points=n,
        measurements=float(n + np.sum(share)),
        vector=vector,
        mesh=mesh,
        n_wrong=int(np.sum(wrong)),
        wrong=tuple(int(k) for k in np.flatnonzero(wrong)[np.argsort(-z2[wrong])]),
        wrong_chi2=float(np.sum(parts[wrong])),
        wrong_measurements=float(np.sum(1.0 + share[wrong])),
        n_crossed=int(np.sum(crossed)),
    )


def _swept_residuals(
    spaces: Sequence[FreeSpace],
    distance: Callable[[FloatArray], FloatArray],
    batch: tuple[int, ...] = (),
) -> FloatArray:
    """r_j of every sweep or contact of ``spaces`` in order, shape (*batch, n), for a signed
    distance function of (k, 3) points (m) giving shape (*batch, k) (a batch of shapes'
    distances, or one shape's with ``batch`` empty); empty without them."""
    parts = [
        space.residuals(distance(space.samples) if len(space.samples) else np.zeros((*batch, 0)))
        for space in spaces
    ]
    return np.concatenate(parts, axis=-1) if parts else np.zeros((*batch, 0))


def _swept_chi2(r: FloatArray, spaces: Sequence[FreeSpace], spread: float) -> FloatArray:
    """Each sweep's or contact's part of chi^2 (:func:`point_chi2` of r_j^2, the cap at its
    evidence's median sample standard deviation), shape (n,) for the residuals of ``spaces``
    in order; empty without them."""
    if not len(r):
        return np.zeros(0)
    return point_chi2(np.asarray(r, dtype=float) ** 2, _sweep_sigma(spaces), spread)


def _sweep_sigma(spaces: Sequence[FreeSpace]) -> FloatArray:
    """Each sweep's or contact's standard deviation for the mixture (m): its evidence's median
    sample standard deviation, shape (n,) for ``spaces`` in order."""
    return np.concatenate(
        [np.full(s.n_sweeps, float(np.median(s.std)) if len(s.std) else 1.0) for s in spaces]
        or [np.zeros(0)]
    )


def _surface_distance(fit: ClassFit, samples: FloatArray) -> FloatArray:
    """Unsigned distance (m) of ``samples`` to ``fit``'s surface: the class's exact distance, or
    the closest point on a registered mesh."""
    if fit.name in PRIMITIVES:
        return np.abs(PRIMITIVES[fit.name].signed_distance(fit.vector, samples))
    assert fit.mesh is not None
    _, distance, _ = closest_point(fit.mesh, samples)
    return np.asarray(distance)


#: A user mesh counts as a member of a class when the class fitted to its surface lies within
#: this share of the mesh's size from it (a box's mesh: its faces' own flatness).
MEMBER_RMS_SHARE = 0.01

#: Points sampled on a user mesh to fit a class to it.
MEMBER_SAMPLES = 400


def shape_size(mesh: trimesh.Trimesh) -> float:
    """A shape's size (m): the largest extent of its mesh's oriented bounding box, whatever its
    pose."""
    return float(np.max(trimesh.bounds.oriented_bounds(mesh)[1]))


def _one_a_member_of_the_other(
    one: ClassFit, other: ClassFit, generator: np.random.Generator
) -> bool:
    """Whether of the two fits one is a user mesh's and the other a class's whose members, at
    the sizes its fit allows, include that mesh: the class fitted to the registered mesh's
    surface within :data:`MEMBER_RMS_SHARE` of its size, and each of that fit's sizes within 3
    standard deviations of the class fit's, at or above its lower bound, or not measured."""
    meshes = [f for f in (one, other) if f.name not in PRIMITIVES and f.mesh is not None]
    classes = [f for f in (one, other) if f.name in PRIMITIVES and f.name != "plane"]
    if len(meshes) != 1 or len(classes) != 1:
        return False
    mesh, fit = meshes[0].mesh, classes[0]
    assert mesh is not None
    size = shape_size(mesh)
    samples, _ = trimesh.sample.sample_surface(
        mesh, MEMBER_SAMPLES, seed=int(generator.integers(2**31))
    )
    tight = np.tile(np.eye(3) * (MEMBER_RMS_SHARE * size) ** 2, (len(samples), 1, 1))
    member = fit_primitive(fit.name, samples, tight, rng=generator)
    if not member.rms <= MEMBER_RMS_SHARE * size:
        return False
    names = list(member.sizes)
    values = [member.sizes[name] for name in names]
    # a box's extents are named in increasing order, which a lower bound need not keep: any
    # assignment of the mesh's extents to the fit's
    orders = itertools.permutations(values) if fit.name == "box" else [values]
    return any(_sizes_allowed(dict(zip(names, order, strict=True)), fit) for order in orders)


def _sizes_allowed(sizes: Mapping[str, float], fit: ClassFit) -> bool:
    """Whether ``sizes`` (m, by name) are among those ``fit`` allows: each within 3 standard
    deviations of its size, at or above its lower bound, or not measured."""
    for name, value in sizes.items():
        std = fit.size_std.get(name, math.inf)
        if name in fit.size_at_least:
            if value < fit.size_at_least[name] - 3.0 * (0.0 if math.isinf(std) else std):
                return False
        elif math.isfinite(std) and abs(value - fit.sizes[name]) > 3.0 * std:
            return False
    return True


def _scatter_narrowed(simpler: ClassFit, richer: ClassFit, level: float = NESTED_LEVEL) -> bool:
    """Whether a class that holds ``simpler``'s shape as its own special case narrows the
    points' scatter about it by more than its extra parameters would by fitting noise: the F
    test of nested least squares at ``level``, F = ((RSS_s - RSS_r) / k) / (RSS_r / (n - p_r))
    with RSS the points' squared distances (n RMS^2), k the extra parameters and p_r the
    richer's. It reads the points' own scatter, not their covariances, which may be wider than
    the points' errors. False when the test cannot be made (no extra parameter, no residual
    degree of freedom, a perfect fit)."""
    n = simpler.n_points
    extra, left = richer.dof - simpler.dof, n - richer.dof
    if extra <= 0 or left <= 0 or not richer.rms > 0.0:
        return False
    statistic = (simpler.rms**2 / richer.rms**2 - 1.0) * left / extra
    return bool(statistic > f_distribution.ppf(level, extra, left))


def shape_gap(a: ClassFit, b: ClassFit, seed: int = 0) -> float:
    """How far two fitted shapes are apart (m): the 95th percentile of the distances from
    :data:`SHAPE_SAMPLES` points on each surface to the other surface; inf when either is
    unbounded (a plane) or has no mesh."""
    if a.mesh is None or b.mesh is None:
        return math.inf
    gaps = []
    for one, other in ((a, b), (b, a)):
        assert one.mesh is not None
        samples, _ = trimesh.sample.sample_surface(one.mesh, SHAPE_SAMPLES, seed=seed)
        gaps.append(_surface_distance(other, np.asarray(samples)))
    return float(np.percentile(np.concatenate(gaps), 95.0))


def _fit_normals(fit: ClassFit, points: FloatArray) -> FloatArray:
    """The fitted surface's unit normals at ``points`` (a mesh's: of its closest faces)."""
    if fit.name in PRIMITIVES:
        return PRIMITIVES[fit.name].normals(fit.vector, points)
    assert fit.mesh is not None
    _, _, faces = closest_point(fit.mesh, points)
    return np.asarray(fit.mesh.face_normals[faces])


def _outward(points: FloatArray, outward: ArrayLike | None) -> FloatArray:
    if outward is not None:
        direction = np.asarray(outward, dtype=float).reshape(3)
    else:
        direction = points.mean(axis=0) * -1.0  # towards the origin, the usual base
    norm = float(np.linalg.norm(direction))
    return direction / norm if norm > 0 else np.array([0.0, 0.0, 1.0])


def confidence_floor(threshold: float) -> float:
    """The best class's weight against one runner-up ``threshold`` behind in score,
    1 / (1 + exp(-threshold / 2)): at the abstention threshold, the confidence a decision needs
    (module docstring)."""
    return 1.0 / (1.0 + math.exp(-0.5 * threshold))


def recognise(
    points: ArrayLike,
    covariances: ArrayLike,
    classes: Sequence[str] | None = None,
    meshes: Mapping[str, trimesh.Trimesh] | None = None,
    outward: ArrayLike | None = None,
    threshold: float = ABSTAIN_DELTA,
    rng: np.random.Generator | None = None,
    lines: LinkLines | None = None,
    swept: Sequence[FreeSpace] = (),
    class_fitted: Callable[[str], None] | None = None,
) -> Recognition:
    """Fit every class (and mesh) to the points and decide (module docstring).

    Parameters
    ----------
    points : array, shape (n, 3)
        World points (m); at least 10 (more than the largest class's 9 parameters).
    covariances : array, shape (n, 3, 3)
        Their covariances (m^2).
    classes : sequence of str, optional
        Primitive classes to try (all of :data:`PRIMITIVES` when None).
    meshes : Mapping[str, trimesh.Trimesh], optional
        User meshes by name, registered at their own size.
    outward : array, shape (3,), optional
        Direction from the object towards the antenna (see :func:`fit_primitive`).
    threshold : float
        Abstain when the runner-up's score is within this of the best's, or the best's weight
        is below 1 / (1 + exp(-threshold / 2)).
    rng : numpy.random.Generator, optional
        Seeded default when None.
    lines : LinkLines, optional
        The link's line at each contact (module docstring).
    swept : sequence of FreeSpace
        Where links swept untouched and where they touched (module docstring).
    class_fitted : callable, optional
        Called with each class's (or mesh's) name once it is fitted: a progress display's hook.
    """
    p = np.asarray(points, dtype=float).reshape(-1, 3)
    cov = np.asarray(covariances, dtype=float).reshape(-1, 3, 3)
    if len(p) < 10:
        raise ValueError(f"recognition needs at least 10 points, got {len(p)}")
    generator = rng if rng is not None else np.random.default_rng(0)
    names = list(classes) if classes is not None else list(PRIMITIVES)
    fits = []
    for name in names:
        fits.append(fit_primitive(name, p, cov, outward, generator, lines, swept))
        if class_fitted is not None:
            class_fitted(name)
    for name, mesh in (meshes or {}).items():
        fits.append(fit_mesh(name, mesh, p, cov, generator, lines=lines, swept=swept))
        if class_fitted is not None:
            class_fitted(name)
    # overdispersion: the best-fitting class's reduced chi^2 when above 1
    tightest = min(fits, key=lambda f: f.chi2)
    c = max(1.0, tightest.chi2 / max(tightest.counted - tightest.dof, 1.0))
    fit_chance = _fit_chance(tightest)
    n_log = math.log(len(p))
    # the sizes' standard deviations widened by the same overdispersion
    fits = [
        dataclasses.replace(
            f,
            score=f.chi2 / c + f.dof * n_log,
            size_std={k: v * math.sqrt(c) for k, v in f.size_std.items()},
            covariance=f.covariance * c,
            size_at_least={
                k: max(f.sizes[k] - (f.sizes[k] - v) * math.sqrt(c), 0.0)
                for k, v in f.size_at_least.items()
            },
        )
        for f in fits
    ]
    fits.sort(key=lambda f: f.score)
    raw = np.exp(-0.5 * (np.array([f.score for f in fits]) - fits[0].score))
    weights = raw / raw.sum()
    fits = [dataclasses.replace(f, weight=float(w)) for f, w in zip(fits, weights, strict=True)]
    best = fits[0]
    sigma = float(np.median(_normal_sigma(cov, _fit_normals(best, p))))
    # a runner-up whose fitted shape is the best's (a capsule shrunk to a ball: apart by no
    # more than the points scatter about the best) and which the points do not tell from it
    # (chi^2 / c within the threshold) is the same answer under another class's name: the
    # best and it score as one class, their weights added, and the decision is between shapes
    gaps: dict[str, float] = {}

    def gap(f: ClassFit) -> float:
        # each runner-up's shape compared with the best's once (2000 samples each way)
        if f.name not in gaps:
            gaps[f.name] = shape_gap(best, f)
        return gaps[f.name]

    def same_shape(f: ClassFit) -> bool:
        # apart by no more than the points scatter about the best; or a class that holds the
        # best's shape as its own special case (a capsule of no segment is a ball), not apart
        # by as much as a rival must be, whose extra parameters narrow the points' own scatter
        # no more than fitting noise does; or a user's mesh and a class one of whose members,
        # within the class fit's sizes, the mesh is (a box, where the points leave its height
        # a lower bound the mesh's meets)
        if gap(f) <= best.rms:
            return True
        if _one_a_member_of_the_other(best, f, generator):
            return True
        return (
            f.name in PRIMITIVES
            and best.name in PRIMITIVES[f.name].holds
            and gap(f) <= SAME_SHAPE_SIGMAS * sigma
            and not _scatter_narrowed(best, f)
        )

    same = [
        f
        for f in fits[1:]
        if f.score - best.score < SAME_SHAPE_SCORE * threshold
        and abs(best.chi2 - f.chi2) / c < threshold
        and same_shape(f)
    ]
    merged = {f.name for f in same}
    others = [f for f in fits[1:] if f.name not in merged]
    group = best.weight + sum(f.weight for f in same)
    group_score = best.score - 2.0 * math.log(group / best.weight)
    delta = others[0].score - group_score if others else math.inf
    # a rival: not ruled out by the likelihood, and a different object
    rival = next(
        (
            f
            for f in others
            if (f.chi2 - best.chi2) / c < threshold and gap(f) > SAME_SHAPE_SIGMAS * sigma
        ),
        None,
    )
    confidence = min(1.0, group)
    if rival is not None:
        # the best's weight against the rival on the likelihood alone
        confidence = confidence_floor((rival.chi2 - best.chi2) / c)
    sure = confidence >= confidence_floor(threshold)
    # a swept link through the best shape, or a touching one far from it, refutes it as the
    # object's whole shape whatever the other classes score
    whole = best.n_crossed == 0
    # and points farther from every class than their deviations allow are of none of them
    named = (
        delta >= threshold and rival is None and sure and whole and not no_class_fits(fit_chance, c)
    )
    decision = best.name if named else UNDECIDED
    leaders = (best, rival) if rival is not None else (best, *others[:1])
    return Recognition(
        decision=decision,
        fits=tuple(fits),
        candidates=tuple(f.name for f in leaders),
        delta_score=float(delta),
        confidence=confidence,
        threshold=threshold,
        overdispersion=float(c),
        fit_chance=fit_chance,
        rival=None if rival is None else rival.name,
        same_shape=tuple(f.name for f in same),
        runner_up=others[0].name if others else None,
    )
