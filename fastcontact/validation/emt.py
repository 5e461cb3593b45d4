"""Generalized Bruggeman effective medium with a percolation threshold (reference version).

The 2-D Bruggeman equation of the shipped ``"emt"`` theory,
``∫ du P(u) (σ_eff - σ(u)) / (σ_eff + σ(u)) = 0``, stops the flow exactly when the contact
area fraction A(ζ1)/A0 reaches 1/2. Kirkpatrick's generalization for a lattice of
coordination number z (S. Kirkpatrick, Rev. Mod. Phys. 45, 574 (1973),
doi:10.1103/RevModPhys.45.574, eq. 5.8),

    Σ_i P(σ_i) (σ_i - σ_m) / (σ_i + (z/2 - 1) σ_m) = 0,                             (E1)

has the conducting-phase threshold 2/z, i.e. the insulating (contact) phase blocks the flow
at the area fraction A_c = 1 - 2/z. With k ≡ z/2 - 1 = A_c/(1 - A_c), the contact phase
(σ = 0, weight A1 = A(ζ1)/A0) and the open phases of P(u) (weights W_j, σ_j = u1(ζ_j)³/12η,
Lorenz & Persson 2010, arXiv:0911.3019) give

    Σ_j W_j (σ_j - σ_m) / (σ_j + k σ_m) - A1 / k = 0,                                (E2)

which has a root σ_m > 0 if and only if A1 < A_c; σ_m = 0 (flow stops) otherwise. A_c = 1/2
(z = 4, k = 1) is the shipped 2-D Bruggeman theory.

P(u) is integrated in the variable A on [A1, 1] with composite Gauss–Legendre panels graded
towards both ends (A = A1 + (1 - A1) t³/(t³ + (1-t)³)); at each node ζ solves
A(ζ) = A_node (bisection in ln q on the PSD's third moment) and u1(ζ) comes from
:func:`fastcontact.contact.u1`, whose masked entries (dA/dζ = 0) carry zero weight.
This quadrature is independent of the shipped adaptive Gauss–Kronrod one; with the
defaults (panel doubling to 1e-8) it agrees with it to ~1e-9 relative at A_c = 1/2.
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["emt_sigma_bar", "emt_conductivity", "threshold_k"]

#: composite Gauss–Legendre panels × order of the quadrature over A
N_PANELS = 24
ORDER = 8
#: panels are doubled until two successive results agree to TOL (at most MAX_PANELS; a
#: RuntimeWarning says so where that limit ends the doubling: at contact-area fractions
#: A(ζ1)/A0 ~ 1e-7 successive results scatter by 1e-8–1e-7 however many panels)
TOL = 1e-8
MAX_PANELS = 768
GRADE = 3.0


def threshold_k(threshold):
    """k = z/2 - 1 = A_c/(1 - A_c) of (E2) for the contact-area threshold A_c ∈ (0, 1)."""
    t = float(threshold)
    if not (0.0 < t < 1.0):
        raise ValueError(f"emt_threshold = {threshold!r} is invalid: must lie in (0, 1) [-]")
    return t / (1.0 - t)


def _zeta_at_area(psd, pbar, area):
    """ζ with A(ζ) = area at reduced pressure p̄ (vectorized bisection in ln q)."""
    from scipy.special import erfinv

    x = erfinv(area)
    # A = erf(p̄ / (2 √Ḡ)), Ḡ = (π/4) m3(ζ)  ->  m3 = 4 Ḡ/π = p̄² / (π x²)
    target = pbar ** 2 / (math.pi * x ** 2)
    lo = np.full(target.shape, math.log(psd.q0))
    hi = np.full(target.shape, math.log(psd.q1))
    for _ in range(64):
        mid = 0.5 * (lo + hi)
        m = np.asarray(psd.moment(3.0, psd.q0, np.exp(mid)))
        below = m < target
        lo = np.where(below, mid, lo)
        hi = np.where(below, hi, mid)
    return np.exp(0.5 * (lo + hi)) / psd.q0


def _nodes(n_panels):
    # numpy's rule directly, not kernels.quadrature: this reference shares no code with the
    # engine it checks
    x, w = np.polynomial.legendre.leggauss(ORDER)
    edges = np.linspace(0.0, 1.0, n_panels + 1)
    half = 0.5 * np.diff(edges)
    mid = 0.5 * (edges[1:] + edges[:-1])
    t = (mid[:, None] + half[:, None] * x[None, :]).ravel()
    wt = (half[:, None] * w[None, :]).ravel()
    m = GRADE
    tm, om = t ** m, (1.0 - t) ** m
    s = tm / (tm + om)
    ds = m * (t * (1.0 - t)) ** (m - 1.0) / (tm + om) ** 2
    return s, ds * wt


def _solve(W, sig, A1, k):
    """Root σ_m of (E2) in reduced units, 0 if A1 >= A_c."""
    from scipy.optimize import brentq

    ok = np.isfinite(sig) & (W > 0)
    W, sig = W[ok], sig[ok]
    if A1 >= k / (1.0 + k) or sig.size == 0 or sig.max() <= 0.0:
        return 0.0

    def f(y):
        s = math.exp(y)
        return float(np.sum(W * (sig - s) / (sig + k * s))) - A1 / k

    hi = math.log(sig.max()) + 1.0
    lo = hi - 5.0
    while f(lo) <= 0.0:
        lo -= 5.0
        if lo < -1400.0:
            return 0.0
    return math.exp(brentq(f, lo, hi, xtol=1e-14, rtol=1e-13))


_CACHE = {}
_CACHE_MAX = 2048


def _weights_sigma(psd, fp, pb, A1, gamma, n_panels):
    """Node weights W_j and reduced σ_j = (u1/h_rms)³ (inf = masked) at one pressure.

    They do not depend on the threshold, so a fit that varies only the threshold reuses them
    (cached per PSD fingerprint, p̄, γ and panel count)."""
    from .. import contact

    key = (fp, pb, gamma, n_panels)
    hit = _CACHE.get(key)
    if hit is not None:
        return hit
    s_nodes, w_nodes = _nodes(n_panels)
    area = A1 + (1.0 - A1) * s_nodes
    W = (1.0 - A1) * w_nodes
    inside = (area > A1) & (area < 1.0)
    zeta = np.ones_like(area)
    zeta[inside] = np.clip(_zeta_at_area(psd, pb, area[inside]), 1.0, psd.zeta1)
    u1 = contact.u1(psd, pb, 1.0, zeta, gamma=gamma)
    sig = np.where(np.ma.getmaskarray(u1) | ~inside, np.inf,
                   (np.maximum(np.ma.getdata(u1), 0.0) / psd.h_rms) ** 3)
    if len(_CACHE) >= _CACHE_MAX:
        _CACHE.clear()
    _CACHE[key] = (W, sig)
    return W, sig


def emt_sigma_bar(psd, pbar, *, threshold=0.5, gamma=1.0):
    """Reduced conductivity σ̄ = 12ησ_eff/h_rms³ of the generalized medium (E2) [-].

    Parameters
    ----------
    psd : fastcontact PSD
        Roughness spectrum (Persson convention).
    pbar : array_like
        Reduced contact pressures p/E* [-], > 0.
    threshold : float
        Contact-area fraction A_c ∈ (0, 1) at which the flow stops (1/2 = shipped Bruggeman).
    gamma : float
        Yang–Persson factor of u1(ζ) (1 = the paper's A4).
    """
    from scipy.special import erf

    k = threshold_k(threshold)
    pbar = np.atleast_1d(np.asarray(pbar, dtype=np.float64))
    if np.any(~np.isfinite(pbar)) or np.any(pbar <= 0):
        raise ValueError(f"pbar = {pbar!r} is invalid: must be finite and > 0 [-]")
    m3_1 = float(np.asarray(psd.moment(3.0, psd.q0, psd.q1)))
    fp = psd.fingerprint() if hasattr(psd, "fingerprint") else repr(psd)
    out = np.empty(pbar.size)
    for i, pb in enumerate(pbar):
        A1 = float(erf(pb / (2.0 * math.sqrt(0.25 * math.pi * m3_1))))
        if A1 >= threshold:
            out[i] = 0.0
            continue
        prev = None
        n_panels = N_PANELS
        while True:
            W, sig = _weights_sigma(psd, fp, float(pb), A1, float(gamma), n_panels)
            val = _solve(W, sig, A1, k)
            if prev is not None and abs(val - prev) <= TOL * abs(val):
                break
            if n_panels >= MAX_PANELS:
                _not_converged(pb, val, prev)
                break
            prev = val
            n_panels *= 2
        out[i] = val
    return out


def _not_converged(pb, val, prev):
    """Warn that the panel doubling at p̄ = ``pb`` reached MAX_PANELS without two results
    agreeing to TOL (the finer value is returned; where the doubling converges fast its error
    is well below the last change, where it scatters it is about that change)."""
    import warnings

    change = abs(val - prev) / abs(val) if prev is not None and val != 0.0 else math.nan
    warnings.warn(f"emt_sigma_bar: at p/E* = {pb:.3g} the panel doubling reached MAX_PANELS = "
                  f"{MAX_PANELS} without two results agreeing to TOL = {TOL:g} (last change "
                  f"{change:.1e}: the finer result's error is not shown to be below TOL)",
                  RuntimeWarning, stacklevel=3)


def emt_conductivity(psd, p, E_star, eta, *, threshold=0.5, gamma=1.0):
    """σ_eff(p_cont) [m³/(Pa·s)] of the generalized Bruggeman medium (E1)–(E2).

    Parameters
    ----------
    psd : fastcontact PSD
        Roughness spectrum C(q) [m⁴] (Persson convention).
    p : array_like
        Contact pressure [Pa], > 0.
    E_star : float
        Contact modulus [Pa], > 0.
    eta : float
        Viscosity [Pa·s], > 0.
    threshold : float
        Contact-area fraction at which flow stops, in (0, 1); 0.5 = the shipped theory.
    gamma : float
        Yang–Persson factor.

    Returns
    -------
    ndarray
        σ_eff [m³/(Pa·s)] of p's shape; exactly 0 where A(ζ1)/A0 >= threshold.
    """
    p_arr = np.asarray(p, dtype=np.float64)
    for name, v, unit in (("E_star", E_star, "[Pa]"), ("eta", eta, "[Pa·s]")):
        if not (float(v) > 0.0 and math.isfinite(float(v))):
            raise ValueError(f"{name} = {v!r} is invalid: must be finite and > 0 {unit}")
    if np.any(~np.isfinite(p_arr)) or np.any(p_arr <= 0):
        raise ValueError(f"p = {p!r} is invalid: must be finite pressures > 0 [Pa]")
    sb = emt_sigma_bar(psd, p_arr.ravel() / float(E_star), threshold=threshold, gamma=gamma)
    return (sb * psd.h_rms ** 3 / (12.0 * float(eta))).reshape(p_arr.shape)
