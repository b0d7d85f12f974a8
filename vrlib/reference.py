"""The reference renderer: the ground truth for every error figure.

It renders a continuous analytic field (from :mod:`data_gen`), not a sampled volume, so it
depends on no sampling lattice and no reconstruction filter. Along each ray the
emission-absorption integral (eqs 1.2-1.3) is computed to a stated tolerance by adaptive
Gauss-Legendre quadrature:

* each ray's stretch inside the field's box is cut into segments;
* on a segment ``[a, b]`` the optical depth ``tau = int Omega`` and the emitted light
  ``C = int E Omega exp(-int_a^t Omega) dt`` are computed with ``n`` Gauss nodes, the inner
  integral with the spectral integration matrix of the same nodes (exact for polynomials of
  degree below ``n``);
* a segment is accepted when its two halves agree with it to within its share of the
  tolerance, and split otherwise;
* accepted segments are composited front to back.

The alpha of a pixel is ``1 - exp(-sum tau)``; with the glow transfer function that is the
closed form ``1 - exp(-k * line integral)``.
"""

from __future__ import annotations

import time

import numpy as np

from vrlib import validate
from vrlib.arguments import check_transfer, framed_view
from vrlib.image import Image, RenderStats
from vrlib.volume import check_extent

__all__ = ["render_reference"]

_NODES = 8
_MAX_DEPTH = 40


def _quadrature(n):
    """Gauss-Legendre nodes and weights on [-1, 1] and the integration matrix
    ``S[i, j] = int_{-1}^{x_i} L_j(x) dx`` of the Lagrange basis at the nodes."""
    x, w = np.polynomial.legendre.leggauss(n)
    vander = np.polynomial.legendre.legvander(x, n - 1)
    coeffs = np.linalg.inv(vander)  # column j: Legendre coefficients of L_j
    S = np.empty((n, n))
    for j in range(n):
        anti = np.polynomial.legendre.legint(coeffs[:, j], lbnd=-1.0)
        S[:, j] = np.polynomial.legendre.legval(x, anti)
    return x, w, S


_X, _W, _S = _quadrature(_NODES)


def _clip_to_box(origins, directions, lo, hi):
    with np.errstate(divide="ignore", invalid="ignore"):
        ta = (lo - origins) / directions
        tb = (hi - origins) / directions
    near = np.where(directions != 0, np.minimum(ta, tb), -np.inf)
    far = np.where(directions != 0, np.maximum(ta, tb), np.inf)
    parallel_outside = (directions == 0) & ((origins < lo) | (origins > hi))
    t_in = np.maximum(near.max(axis=-1), 0.0)
    t_out = far.min(axis=-1)
    t_out = np.where(parallel_outside.any(axis=-1), t_in, np.maximum(t_out, t_in))
    return t_in, t_out


class _Segments:
    """Evaluates ``(tau, C)`` of many segments at once with the Gauss rule."""

    def __init__(self, field, transfer, origins, directions):
        self.field, self.transfer = field, transfer
        self.origins, self.directions = origins, directions
        self.evaluations = 0

    def integrate(self, ray, a, b):
        half = 0.5 * (b - a)
        t = 0.5 * (a + b)[:, None] + half[:, None] * _X[None, :]
        d = self.directions[ray][:, None, :]
        points = self.origins[ray][:, None, :] + t[..., None] * d
        values = self.field(points)
        self.evaluations += values.size
        omega = self.transfer.opacity_density(values)
        emit = self.transfer.emission(values)
        shading = self.transfer.shading
        ramp = self.transfer.gradient_opacity
        grad = self.field.gradient(points) if self.transfer.needs_gradient else None
        if ramp is not None:
            omega = omega * ramp.factor(np.linalg.norm(grad, axis=-1))
        if shading is not None:
            # One view direction per segment, the same at each of its nodes.
            view_dir = np.broadcast_to(-self.directions[ray][:, None, :], grad.shape)
            factor = shading.factor(grad, view_dir)
            spec = shading.highlight(grad, view_dir)
            emit = emit * factor[..., None] + spec[..., None]
        tau = half * (omega @ _W)
        inner = half[:, None] * (omega @ _S.T)  # int_a^{t_i} omega, at every node
        weight = (_W[None, :] * omega * np.exp(-inner)) * half[:, None]
        light = np.einsum("sn,snc->sc", weight, emit)
        return tau, light


def render_reference(field, view, *, transfer=None, tol=1e-6, extent=None, segments=32,
                     chunk=4096):
    """Render an analytic field exactly, to a tolerance, for every pixel of ``view``.

    Parameters
    ----------
    field : data_gen.Field
        The continuous field (callable on world points, with ``bounds``).
    view : View
    transfer : TransferFunction, default ``Glow(1.0)``
    tol : float, default 1e-6
        Absolute tolerance per pixel and channel (> 0): each segment's error estimate must be
        below its share ``tol * length / ray length``.
    extent : array_like (3, 2), optional
        The box the field fills (default ``field.bounds``, the box a sampled volume covers).
    segments : int, default 32
        Segments each ray starts with before adaptive splitting (more resolves small features
        that a coarse first pass could miss).
    chunk : int, default 4096
        Rays handled at once (memory).

    Returns
    -------
    Image

    Examples
    --------
    >>> import data_gen, vrlib
    >>> blob = data_gen.make_field("gaussian-blob", sigma=0.3)
    >>> img = render_reference(blob, vrlib.View.orbit(size=4), transfer=vrlib.Glow(2.0))
    >>> o, d = vrlib.View.orbit(size=4).rays()
    >>> t0, t1 = _clip_to_box(o, d, -1.0, 1.0)
    >>> exact = 1 - np.exp(-2.0 * blob.line_integral(o, d, t0, t1))
    >>> bool(np.abs(img.alpha - exact).max() < 1e-6)
    True
    """
    if not callable(field) or not hasattr(field, "bounds"):
        raise TypeError(f"field must be an analytic data_gen field, got {type(field).__name__}")
    transfer = check_transfer(transfer)
    view = framed_view(view, field.bounds if extent is None else extent)
    tol = validate.finite_number("tol", tol, low=0.0, low_open=True)
    segments = validate.positive_int("segments", segments)
    chunk = validate.positive_int("chunk", chunk)
    box = check_extent(field.bounds if extent is None else extent)
    start = time.perf_counter()
    origins, directions = view.rays()
    origins = origins.reshape(-1, 3)
    directions = directions.reshape(-1, 3)
    rgba = np.zeros((origins.shape[0], 4))
    evaluations = 0
    for first in range(0, origins.shape[0], chunk):
        rays = slice(first, first + chunk)
        part, count = _render_rays(field, transfer, origins[rays], directions[rays], box, tol,
                                   segments)
        rgba[rays] = part
        evaluations += count
    stats = RenderStats(samples=evaluations, seconds=time.perf_counter() - start,
                        bytes=int(rgba.nbytes))
    return Image(rgba.reshape(view.shape + (4,)), stats)


def _render_rays(field, transfer, origins, directions, box, tol, segments):
    n_rays = origins.shape[0]
    t_in, t_out = _clip_to_box(origins, directions, box[:, 0], box[:, 1])
    length = t_out - t_in
    hit = np.flatnonzero(length > 0)
    rgba = np.zeros((n_rays, 4))
    if hit.size == 0:
        return rgba, 0
    integrator = _Segments(field, transfer, origins, directions)
    # Initial segments: equal parts, also cut where the field jumps (quadrature needs the
    # integrand smooth inside a segment); then adaptive bisection until each meets its tol.
    cuts = t_in[hit, None] + length[hit, None] * np.linspace(0.0, 1.0, segments + 1)[None, :]
    jumps = field.breakpoints(origins[hit], directions[hit]) if hasattr(
        field, "breakpoints") else None
    if jumps is not None:
        jumps = np.where((jumps > t_in[hit, None]) & (jumps < t_out[hit, None]), jumps, np.nan)
        cuts = np.sort(np.concatenate([cuts, jumps], axis=1), axis=1)  # nan sorts last
    a, b = cuts[:, :-1], cuts[:, 1:]
    keep = b > a  # also drops the pairs that involve nan
    ray = np.broadcast_to(hit[:, None], a.shape)[keep]
    a, b = a[keep], b[keep]
    whole_tau, whole_light = integrator.integrate(ray, a, b)
    done_ray, done_a, done_tau, done_light = [], [], [], []
    for depth in range(_MAX_DEPTH + 1):
        mid = 0.5 * (a + b)
        tau1, light1 = integrator.integrate(ray, a, mid)
        tau2, light2 = integrator.integrate(ray, mid, b)
        # Two halves composited: the second is dimmed by the first's transparency.
        tau_split = tau1 + tau2
        light_split = light1 + np.exp(-tau1)[:, None] * light2
        error = np.maximum(np.abs(tau_split - whole_tau),
                           np.abs(light_split - whole_light).max(axis=1))
        share = tol * (b - a) / length[ray]
        ok = (error <= share) | (depth == _MAX_DEPTH) | (b - a <= 1e-12 * length[ray])
        done_ray.append(ray[ok])
        done_a.append(a[ok])
        done_tau.append(tau_split[ok])
        done_light.append(light_split[ok])
        redo = ~ok
        if not np.any(redo):
            break
        ray = np.concatenate([ray[redo], ray[redo]])
        a, b = np.concatenate([a[redo], mid[redo]]), np.concatenate([mid[redo], b[redo]])
        whole_tau = np.concatenate([tau1[redo], tau2[redo]])
        whole_light = np.concatenate([light1[redo], light2[redo]])
    # Composite every ray's accepted segments front to back (eqs 1.7-1.8).
    ray = np.concatenate(done_ray)
    a = np.concatenate(done_a)
    tau = np.concatenate(done_tau)
    light = np.concatenate(done_light)
    order = np.lexsort((a, ray))
    ray, tau, light = ray[order], tau[order], light[order]
    starts = np.flatnonzero(np.r_[True, ray[1:] != ray[:-1]])
    total = np.add.reduceat(tau, starts)
    cumulative = np.cumsum(tau)
    before = cumulative - tau - np.repeat(cumulative[starts] - tau[starts], np.diff(
        np.r_[starts, ray.size]))
    dimmed = np.exp(-before)[:, None] * light
    rays_hit = ray[starts]
    rgba[rays_hit, :3] = np.add.reduceat(dimmed, starts, axis=0)
    rgba[rays_hit, 3] = -np.expm1(-total)
    return rgba, integrator.evaluations
