"""Line scans → isotropic 2-D spectrum: the Abel-type projection and its regularised inverse.

For isotropic roughness the 1-D spectrum of a straight profile is
``C1D(qx) = 2 ∫_{qx}^∞ C(q) q dq / √(q²-qx²)`` (:func:`abel_forward`); its exact inverse is
``C(q) = -(1/π) ∫_q^∞ C1D'(k) dk / √(k²-q²)`` (:func:`abel_invert`). On measured scans the
inverse amplifies noise, so :func:`abel_fit` fits C by maximum a-posteriori (Whittle
likelihood plus a prior on the change of log-log slope). Conventions: C [m^4] Persson,
C1D [m^3] with ``h_rms² = 2 ∫_0^∞ C1D dq``; see :mod:`fastcontact.surface.topography`.
"""
from __future__ import annotations

import math

import numpy as np
from scipy.special import betainc, beta as beta_fn, gammaln

from .._core.validate import as_float_array
from ..kernels.rules import gauss_legendre

__all__ = ["abel_forward", "abel_invert", "abel_fit", "ABEL_SLOPE_PRIOR"]

_GL_X, _GL_W = gauss_legendre(8)
#: prior std of the change of log-log slope between neighbouring C1D nodes (line scans)
ABEL_SLOPE_PRIOR = 1.0


def _local_slopes(q, v, half_width_decades=0.25):
    """Least-squares log-log slope of v(q) in a ±half_width window around every sample."""
    lq, lv = np.log10(q), np.log(v)
    s = np.empty(q.size)
    for i in range(q.size):
        m = np.abs(lq - lq[i]) <= half_width_decades
        if m.sum() < 2:
            j = np.argsort(np.abs(lq - lq[i]))[:2]
            m = np.zeros(q.size, bool)
            m[j] = True
        x = np.log(q[m])
        s[i] = np.polyfit(x, lv[m], 1)[0]
    return s


def _powerlaw_factor(H):
    """Γ(1+H)/(√π Γ(H+½)): C = factor · C1D/q for C1D ∝ q^{-(1+2H)} (power-law limit of :func:`abel_invert`)."""
    return np.exp(gammaln(1.0 + H) - gammaln(H + 0.5)) / math.sqrt(math.pi)


def _smooth_loglog(q, v, weights, slope_prior):
    """Penalised (Whittaker) smoothing of ln v against ln q (starting guess of the Abel fit).

    Minimises ``Σ w_i (y_i - z_i)² + Σ_i ((s_{i+½} - s_{i-½}) / slope_prior)²``, y = ln v,
    s the segment slopes of z (zero penalty for a power law).
    """
    x, y = np.log(q), np.log(v)
    n = x.size
    if n < 3:
        return np.asarray(v, float)
    D = _slope_change_matrix(x)
    w = np.asarray(weights, float)
    z = np.linalg.solve(np.diag(w) + (D.T @ D) / slope_prior ** 2, w * y)
    return np.exp(z)


def _slope_change_matrix(x):
    """(n-2)×n matrix: change of slope of a piecewise-linear function of x at its inner nodes."""
    n = x.size
    dx = np.diff(x)
    S = np.zeros((n - 1, n))
    j = np.arange(n - 1)
    S[j, j] = -1.0 / dx
    S[j, j + 1] = 1.0 / dx
    return S[1:] - S[:-1]


def abel_invert(q, c1d):
    """Isotropic 2-D C(q) [m^4] at the samples ``q`` from a sampled 1-D spectrum C1D [m³].

    Direct (unregularised) inversion of ``C1D(qx) = ∫ dqy C(√(qx²+qy²))`` for the log-log
    linear interpolant of the samples, continued above ``q[-1]`` by a power law (see the module
    doc): exact for exact data, but it amplifies noise (it is a half-order derivative) — for
    measured scans :func:`psd_from_heights` uses the regularised fit :func:`abel_fit`.
    Returns ``(C, fallback)``, ``fallback`` marking samples where the inversion was
    non-positive and the local power-law factor (H from a ±0.25-decade fit) was used instead.
    """
    q = as_float_array("q", q).ravel()
    d = as_float_array("c1d", c1d).ravel()
    n = q.size
    s = np.log(d[1:] / d[:-1]) / np.log(q[1:] / q[:-1])          # segment slopes
    # tail: fit the top ~0.15 decade (at least the last two samples), cap at -1
    top = q >= q[-1] / 10 ** 0.15
    if top.sum() < 2:
        top[-2:] = True
    s_tail = float(np.polyfit(np.log(q[top]), np.log(d[top]), 1)[0])
    s_tail = min(s_tail, -1.0 - 1e-6)
    C = np.zeros(n)
    for j in range(n):
        qj = q[j]
        # segments i = j .. n-2 : k in [q_i, q_{i+1}], t = arccosh(k/q_j)
        i = np.arange(j, n - 1)
        if i.size:
            ta = np.arccosh(np.maximum(q[i] / qj, 1.0))
            tb = np.arccosh(q[i + 1] / qj)
            half = 0.5 * (tb - ta)
            t = 0.5 * (ta + tb)[:, None] + half[:, None] * _GL_X[None, :]
            k = qj * np.cosh(t)
            dk = d[i][:, None] * (k / q[i][:, None]) ** s[i][:, None]
            f = s[i][:, None] * dk / k                              # C1D'(k)
            C[j] -= np.sum(half * (f @ _GL_W)) / math.pi
        # tail above q[-1]: C1D = d_n (k/q_n)^s, ∫ k^{s-1}/√(k²-q²) dk closed form
        a = 0.5 * (1.0 - s_tail)
        x = (qj / q[-1]) ** 2
        integral = 0.5 * qj ** (s_tail - 1.0) * betainc(a, 0.5, x) * beta_fn(a, 0.5)
        C[j] -= s_tail * d[-1] * q[-1] ** (-s_tail) * integral / math.pi
    bad = ~(np.isfinite(C) & (C > 0))
    if np.any(bad):
        H = np.clip((-_local_slopes(q, d) - 1.0) / 2.0, 0.0, 1.0)
        C[bad] = (_powerlaw_factor(H) * d / q)[bad]
    return C, bad


def abel_forward(q, C, s_tail=None, *, jacobian=False):
    """1-D spectrum C1D(q_j) = 2 ∫_{q_j}^∞ C(k) k dk / √(k²-q_j²) of an isotropic table.

    ``C`` (at the nodes ``q``) is interpolated log-log linearly and continued above ``q[-1]``
    as ``C[-1] (k/q[-1])^s_tail`` (default: the last segment's slope, capped at -2; must be
    < -1). Gauss–Legendre in t (k = q_j cosh t) per segment, closed form for the tail. With
    ``jacobian=True`` also returns ``∂C1D_j/∂ln C_i``.
    """
    q = np.asarray(q, float)
    c = np.asarray(C, float)
    n = q.size
    lq = np.log(q)
    L = np.diff(lq)
    e = np.diff(np.log(c)) / L
    if s_tail is None:
        s_tail = min(float(e[-1]), -2.0)
    jj, ii = np.nonzero(np.arange(n)[:, None] <= np.arange(n - 1)[None, :])   # node j, segment i
    qj = q[jj]
    ta = np.arccosh(np.maximum(q[ii] / qj, 1.0))
    tb = np.arccosh(q[ii + 1] / qj)
    half = 0.5 * (tb - ta)
    t = 0.5 * (ta + tb)[:, None] + half[:, None] * _GL_X[None, :]
    k = qj[:, None] * np.cosh(t)
    u = (np.log(k) - lq[ii][:, None]) / L[ii][:, None]               # position in segment
    val = c[ii][:, None] * np.exp(e[ii][:, None] * (np.log(k) - lq[ii][:, None])) * k
    wq = 2.0 * half[:, None] * _GL_W[None, :]
    D = np.bincount(jj, weights=np.sum(wq * val, axis=1), minlength=n)
    a = -0.5 * (s_tail + 1.0)
    tail = (q[-1] ** (-s_tail) * q ** (s_tail + 1.0)
            * betainc(a, 0.5, (q / q[-1]) ** 2) * beta_fn(a, 0.5))  # 2·(q^{s+1}/2)·B(x; a, ½)
    D = D + c[-1] * tail
    if not jacobian:
        return D
    J = np.zeros((n, n))
    np.add.at(J, (jj, ii), np.sum(wq * val * (1.0 - u), axis=1))
    np.add.at(J, (jj, ii + 1), np.sum(wq * val * u, axis=1))
    J[:, -1] += c[-1] * tail
    return D, J


def abel_fit(q, c1d, weights, *, slope_prior=None):
    """Regularised isotropic 2-D C(q) [m^4] at the nodes ``q`` from a measured C1D [m³].

    Maximum a-posteriori fit of the forward projection :func:`abel_forward` of a log-log
    table C to the data: Whittle (exponential / gamma) likelihood of bin-averaged periodogram
    values, ``Σ_j w_j (ln D_j + d_j/D_j)`` with ``w_j`` the node's statistical weight
    (number of independent periodogram values, 0 to ignore a node), plus the Gaussian prior
    ``½ Σ (Δs/slope_prior)²`` on the change of log-log slope of C between neighbouring nodes
    (zero for a power law, so a self-affine band is not biased; default
    :data:`ABEL_SLOPE_PRIOR`). Solved by Fisher scoring (Gauss–Newton) on ln C with the
    analytic Jacobian and backtracking, starting from :func:`abel_invert` of the
    log-smoothed data. Unlike the direct inversion it is unbiased for few-sample bins (ln of
    an exponential variable is biased by -0.58) and it keeps C positive and bounded where
    C1D is nearly flat (the roll-off).
    """
    q = np.asarray(q, float)
    d = np.asarray(c1d, float)
    w = np.asarray(weights, float)
    prior = ABEL_SLOPE_PRIOR if slope_prior is None else float(slope_prior)
    n = q.size
    c0, _ = abel_invert(q, _smooth_loglog(q, d, np.maximum(w, 1e-3), prior))
    if n < 3:
        return c0
    # tail of C beyond the data: from the top ~0.15 decade of C1D, C ∝ q^{s_D - 1}, s <= -2
    top = q >= q[-1] / 10 ** 0.15
    if top.sum() < 2:
        top[-2:] = True
    s_tail = min(float(np.polyfit(np.log(q[top]), np.log(d[top]), 1)[0]) - 1.0, -2.0)
    P = _slope_change_matrix(np.log(q)) / prior
    PtP = P.T @ P

    def evaluate(lc):
        D, J = abel_forward(q, np.exp(lc), s_tail, jacobian=True)
        D = np.maximum(D, 1e-300)
        r = d / D
        f = float(np.sum(w * (np.log(D) + r)) + 0.5 * lc @ PtP @ lc)
        g = J.T @ (w * (1.0 - r) / D) + PtP @ lc
        fisher = (J.T * (w / D ** 2)) @ J + PtP
        return f, g, fisher

    # Fisher scoring (Gauss–Newton for the Whittle likelihood) with backtracking
    lc = np.log(c0)
    f, g, F = evaluate(lc)
    for _ in range(200):
        try:
            step = np.linalg.solve(F + 1e-10 * np.trace(F) / n * np.eye(n), g)
        except np.linalg.LinAlgError:
            break
        step = np.clip(step, -5.0, 5.0)
        lam = 1.0
        while lam > 1e-6:
            trial = lc - lam * step
            ft, gt, Ft = evaluate(trial)
            if np.isfinite(ft) and ft <= f + 1e-4 * lam * (g @ -step):
                break
            lam *= 0.5
        else:
            break
        converged = abs(f - ft) <= 1e-12 * (abs(f) + 1.0) and np.max(np.abs(lam * step)) < 1e-8
        lc, f, g, F = trial, ft, gt, Ft
        if converged or np.max(np.abs(lam * step)) < 1e-10:
            break
    c = np.exp(lc)
    if not np.all(np.isfinite(c) & (c > 0)):
        return c0
    return c
