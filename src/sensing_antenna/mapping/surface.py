"""A surface with uncertainty from contact points: a Gaussian-process implicit surface.

The object's surface is the zero level of a function f(x) that is negative inside and positive
outside, signed-distance-like near the surface (Williams and Fitzgibbon, "Gaussian process
implicit surfaces", 2006; Dragiev, Toussaint and Gienger, ICRA 2011, for touch). f is a
Gaussian process (scikit-learn's GaussianProcessRegressor) around a prior mean m(x), trained on:

- f = 0 at each contact point, with noise variance sigma_n^2 = n^T Sigma n, the point's
  variance along the estimated normal n;
- f = +e at p + e n and f = -e at p - e n (off-surface points, e = :attr:`offset`), the normal
  from the principal axes of the point's nearest neighbours, oriented towards the antenna's base
  (the link reached the point from there, so that side is outside).

The prior mean is the algebraic sphere through the points, m(x) = +-(|x - c| - r) (a closed shape
where the data are silent; minus when the bases lie inside it, a hollow), and the normals are
oriented like its radius; a plane through the points facing the bases when the sphere is larger
than twice the points' spread. The kernel is
a constant times a squared exponential, its length scale and amplitude fitted by maximum
marginal likelihood within :attr:`length_scale_bounds`. The predictive standard deviation of f
(m, near the surface) is the surface's uncertainty; the mesh is the zero level by marching
cubes (scikit-image), kept where a contact lies within a quarter of the points' spread.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np
import trimesh
from numpy.typing import ArrayLike, NDArray
from scipy.spatial import cKDTree
from skimage.measure import marching_cubes
from sklearn.exceptions import ConvergenceWarning
from sklearn.gaussian_process import GaussianProcessRegressor
from sklearn.gaussian_process.kernels import RBF, ConstantKernel

__all__ = ["MIN_SURFACE_POINTS", "ImplicitSurface"]

FloatArray = NDArray[np.float64]

#: Fewest points a surface is fitted to: the normals need neighbours (3 besides the point).
MIN_SURFACE_POINTS = 4

#: The mesh is kept within this fraction of the points' spread of a contact: beyond, the prior
#: speaks, not the points. Not the kernel's length scale: its marginal likelihood has an optimum
#: near each bound, and the fit moves between them as contacts are added (docs/design-notes.md,
#: "The surface's reach").
REACH_SPREAD = 0.25


@dataclass
class ImplicitSurface:
    """Gaussian-process implicit surface (scikit-learn's fit / predict shape).

    Parameters
    ----------
    offset : float
        e, distance of the off-surface points from each contact (m); capped at a quarter of the
        points' spread so that inside points stay inside small objects.
    length_scale_bounds : tuple of float
        Range of the kernel's length scale (m).
    neighbours : int
        Points whose principal axes give a point's normal (itself included).
    random_state : int
        Seed of the marginal-likelihood optimiser's restarts.
    """

    offset: float = 0.005
    length_scale_bounds: tuple[float, float] = (0.01, 1.0)
    neighbours: int = 8
    random_state: int = 0

    def fit(self, points: ArrayLike, covariances: ArrayLike, outside: ArrayLike) -> ImplicitSurface:
        """Fit to contact points.

        Parameters
        ----------
        points : array, shape (n, 3)
            Contact points (m), n >= :data:`MIN_SURFACE_POINTS`.
        covariances : array, shape (n, 3, 3)
            Their covariances (m^2).
        outside : array, shape (n, 3) or (3,)
            A point on the outer side of each contact (the antenna's base, m).
        """
        p = np.asarray(points, dtype=float).reshape(-1, 3)
        cov = np.asarray(covariances, dtype=float).reshape(-1, 3, 3)
        n = len(p)
        if n < MIN_SURFACE_POINTS:
            raise ValueError(f"a surface needs at least {MIN_SURFACE_POINTS} points, got {n}")
        base = np.broadcast_to(np.asarray(outside, dtype=float), (n, 3))
        normals = self._normals(p, base)
        self._set_prior(p, base)
        if self.prior_radius_ is not None:
            # orient the normals like the prior sphere's (the base only says which side of
            # the sphere is out; a point seen side-on says nothing by itself)
            radial = (p - self.prior_centre_) * self.prior_sign_
            normals[np.einsum("ni,ni->n", normals, radial) < 0] *= -1.0
        # sigma_n^2 = n^T Sigma n
        noise = np.einsum("ni,nij,nj->n", normals, cov, normals)
        noise = np.maximum(noise, 1e-12)
        spread = float(np.linalg.norm(p.max(axis=0) - p.min(axis=0)))
        e = min(self.offset, 0.25 * spread) if spread > 0 else self.offset
        x = np.vstack([p, p + e * normals, p - e * normals])
        y = np.concatenate([np.zeros(n), np.full(n, e), np.full(n, -e)])
        alpha = np.concatenate([noise, noise, noise])
        kernel = ConstantKernel(e**2, (1e-8, 1.0)) * RBF(
            length_scale=math.sqrt(self.length_scale_bounds[0] * self.length_scale_bounds[1]),
            length_scale_bounds=self.length_scale_bounds,
        )
        self.gp_ = GaussianProcessRegressor(
            kernel=kernel, alpha=alpha, normalize_y=False, random_state=self.random_state
        )
        with warnings.catch_warnings():
            # a length scale at its bound is an answer (the prior explains the points, or they
            # vary on the finest scale allowed), not a failure
            warnings.simplefilter("ignore", ConvergenceWarning)
            self.gp_.fit(x, y - self.prior_mean(x))
        self.points_ = p
        self.normals_ = normals
        self.length_scale_ = float(self.gp_.kernel_.k2.length_scale)
        self.offset_ = e
        return self

    def prior_mean(self, x: ArrayLike) -> FloatArray:
        """m(x) (m), shape (n,)."""
        q = np.asarray(x, dtype=float).reshape(-1, 3)
        if self.prior_radius_ is not None:
            distance = np.linalg.norm(q - self.prior_centre_, axis=1) - self.prior_radius_
            return np.asarray(self.prior_sign_ * distance)
        return np.asarray((q - self.prior_centre_) @ self.prior_normal_)

    def predict(
        self, x: ArrayLike, return_std: bool = False
    ) -> FloatArray | tuple[FloatArray, FloatArray]:
        """f(x) (m), shape (n,); with ``return_std`` also its standard deviation (m)."""
        q = np.asarray(x, dtype=float).reshape(-1, 3)
        if return_std:
            mean, std = self.gp_.predict(q, return_std=True)
            return np.asarray(mean + self.prior_mean(q)), np.asarray(std)
        return np.asarray(self.gp_.predict(q) + self.prior_mean(q))

    def score(self, points: ArrayLike) -> float:
        """RMS of f at points known to lie on the surface (m): 0 for a perfect surface."""
        return float(np.sqrt(np.mean(np.asarray(self.predict(points)) ** 2)))

    def mesh(self, resolution: int = 40) -> tuple[trimesh.Trimesh, FloatArray]:
        """The zero level as a mesh and the predictive std at its vertices (m).

        Marching cubes on a ``resolution``^3 grid over the points' bounding box padded by a
        quarter of their spread (and the offset), kept where a contact lies within
        :data:`REACH_SPREAD` of the points' spread. The mesh may be empty when the zero level
        does not cross the grid.
        """
        spread = float(np.linalg.norm(self.points_.max(axis=0) - self.points_.min(axis=0)))
        reach = REACH_SPREAD * spread
        pad = 0.25 * spread + self.offset_
        low = self.points_.min(axis=0) - pad
        high = self.points_.max(axis=0) + pad
        axes = [np.linspace(lo, hi, resolution) for lo, hi in zip(low, high, strict=True)]
        grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
        values = np.asarray(self.predict(grid)).reshape((resolution,) * 3)
        if not (values.min() < 0.0 < values.max()):
            return trimesh.Trimesh(), np.zeros(0)
        spacing = tuple(float(a[1] - a[0]) for a in axes)
        vertices, faces, _, _ = marching_cubes(values, level=0.0, spacing=spacing)
        vertices = vertices + low
        near = cKDTree(self.points_).query(vertices)[0] <= reach
        keep = near[faces].all(axis=1)
        mesh = trimesh.Trimesh(vertices=vertices, faces=faces[keep], process=False)
        mesh.remove_unreferenced_vertices()
        _, std = self.predict(mesh.vertices, return_std=True)
        return mesh, np.asarray(std)

    def _normals(self, p: FloatArray, base: FloatArray) -> FloatArray:
        k = min(self.neighbours, len(p))
        _, index = cKDTree(p).query(p, k=k)
        normals = np.empty_like(p)
        for i, neighbours in enumerate(np.atleast_2d(index)):
            local = p[neighbours] - p[neighbours].mean(axis=0)
            normals[i] = np.linalg.svd(local)[2][2]
        # orient each towards its base: the outer side
        flip = np.einsum("ni,ni->n", normals, base - p) < 0
        normals[flip] *= -1.0
        return normals

    def _set_prior(self, p: FloatArray, base: FloatArray) -> None:
        a = np.hstack([2.0 * p, np.ones((len(p), 1))])
        b = np.sum(p**2, axis=1)
        solution, *_ = np.linalg.lstsq(a, b, rcond=None)
        centre = solution[:3]
        radius_sq = float(solution[3] + centre @ centre)
        spread = float(np.linalg.norm(p.max(axis=0) - p.min(axis=0)))
        # the sphere, if it is of the points' scale: convex (sign +1) when most bases lie
        # outside it, a hollow (sign -1) otherwise
        if radius_sq > 0 and math.sqrt(radius_sq) < 2.0 * spread:
            self.prior_centre_ = centre
            self.prior_radius_: float | None = math.sqrt(radius_sq)
            outside = np.linalg.norm(base - centre, axis=1) > self.prior_radius_
            self.prior_sign_ = 1.0 if np.mean(outside) >= 0.5 else -1.0
            return
        normal = (base - p).mean(axis=0)
        self.prior_centre_ = p.mean(axis=0)
        self.prior_normal_ = normal / max(float(np.linalg.norm(normal)), 1e-12)
        self.prior_radius_ = None
