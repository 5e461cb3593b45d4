"""Surface topography → power spectrum C(q), spectrum files, synthetic surfaces (SPEC §1).

Glossary
--------
h(x)        surface heights [m] on a regular grid of ``spacing`` a [m]
N, M        map size: ``heights.shape == (N, M)`` (rows, columns); a line scan has M samples
L           scan length, L = M a (a map's longest side sets q_lo) [m]
q_lo        smallest wavevector of the returned spectrum: 2π/L for line scans; for a 2-D
            map the equal-area radius of the origin's lattice cell, √(Δqx Δqy/π) ≈ 0.56·2π/L
            (the cells of the lowest shell at 2π/L reach down to it) [1/m]
q_Ny        Nyquist wavevector π/a [1/m]
C(q)        isotropic 2-D spectrum, Persson convention [m^4],
            C(q) = (2π)^-2 ∫ d²x <h(x)h(0)> e^{-iq·x},  h_rms² = 2π ∫ q C dq
C1D(q)      1-D (line-scan) spectrum [m^3],
            C1D(q) = (2π)^-1 ∫ dx <h(x)h(0)> e^{-iqx},  h_rms² = 2 ∫_0^∞ C1D dq
H           Hurst exponent [-]

Conventions and normalisations
------------------------------
2-D map, periodic FFT ``Z = fft2(h)`` (SPEC §1, generalised to N×M)::

    C(q_k) = a² |Z_k|² / ((2π)² N M),        so  mean(h²) = Σ_{k≠0} C(q_k) Δqx Δqy

Line scan, ``Z = fft(h)`` of M samples::

    C1D(q_k) = a |Z_k|² / (2π M),            so  mean(h²) = Σ_{k≠0} C1D(q_k) Δq

**Convention trap.** SurfaceTopography / contact.engineering publish ``(2π)²`` times
Persson's C. Files therefore never carry an implied convention: :func:`read_psd` requires it
and everything returned here is Persson-convention C in SI units.

Binning: area-preserving log-log tables
---------------------------------------
The periodogram values are averaged over log-spaced bins between q_lo and q_Ny (default 10
per decade; for a 2-D map the lattice points of each annulus, q = 0 and the FFT corners
beyond q_Ny dropped; for line scans the inner edges are snapped to half-integer multiples of
2π/L so that every bin holds whole lattice cells; an empty bin is merged into its neighbour;
bins at either end whose mean is at FFT round-off level, < 1e-24 × the largest — e.g. above
q1 of a synthetic map — are dropped, so the table then ends there instead of at q_lo / q_Ny).
The returned table is *histopolating*: its node values at the geometric bin centres (plus
the end nodes q_lo, flat, and q_Ny, last slope) are chosen so that the log-log interpolant
integrates over each bin to the bin's mean times the bin's area (2-D) / length (1-D). So a
local power law is reproduced exactly (no bin-width bias), every bin keeps its energy, and a
sharp roll-off kink is not rounded off — a plain interpolant through the bin means loses
~1.5 % of the variance at a roll-off with 10 bins per decade, which breaks Parseval.
For a 2-D map the bin edges near the origin (fewer than EQUAL_AREA_MAX_CELLS lattice cells
inside) are moved to equal-area radii, so each of those annuli has exactly the area of the
cells whose energy it carries, and the band starts at the origin cell's equal-area radius;
otherwise the 4 points at 2π/L would be spread over too small an annulus and a spectrum
without a resolved roll-off (most variance in the lowest shells) would lose 4–25 %.
Parseval for a 2-D map (rms of the detrended heights = ``psd.h_rms``) then holds to
≤ 0.07 % without a roll-off (H = 0.3–0.8), ≤ 0.16 % with the roll-off at 16·q_lo and
≤ 0.31 % at 8·q_lo (measured, 6 Gaussian 512² maps each).
:func:`psd_from_heights` warns (RuntimeWarning) when it is above 1 %, i.e. when the map
holds roughness beyond q_Ny (the FFT corners).

Line scans → isotropic 2-D C(q)
-------------------------------
For isotropic roughness the 1-D spectrum of any straight profile is the Abel-type projection
``C1D(qx) = ∫ dqy C(√(qx²+qy²)) = 2 ∫_{qx}^∞ C(q) q dq / √(q²-qx²)`` (:func:`abel_forward`),
whose exact inverse is ``C(q) = -(1/π) ∫_q^∞ C1D'(k) dk / √(k²-q²)`` (:func:`abel_invert`;
for a power law it is SPEC's ``C = Γ(1+H)/(√π Γ(H+½)) C1D/q``). The inverse is a half-order
derivative: on measured scans it turns the ±100 % scatter of the few-sample long-wavelength
bins, where C1D is nearly flat, into C wrong by ×10, and ln of a one-sample bin is biased by
-0.58. :func:`psd_from_heights` therefore *fits* (:func:`abel_fit`): C is a log-log table on
the C1D nodes, projected exactly by :func:`abel_forward` (Gauss–Legendre in k = q cosh t per
power-law segment, closed-form incomplete-beta tail above q_Ny), and ln C maximises the
Whittle likelihood of the bin-averaged periodogram (weights = number of periodogram values
× effective number of independent scans) plus a Gaussian prior (std 1 per node) on the
change of log-log slope — zero for a power law, so the self-affine band is unbiased, and it
keeps the roll-off bounded. Measured on rows of 512² / 1024² synthetic isotropic surfaces
(H = 0.3–0.8, roll-off at 8–32·q_lo), in the self-affine band 2·q_r … q_Ny/3: all rows of
one map: rms error 4 %, worst node 11 % (exact-amplitude maps, i.e. without statistical
scatter: ≤ 0.3 %, ≤ 3 % for H = 0.3); 8 scans: rms 8 %; one scan of 512–1024 points:
rms 16 %, worst node a factor ~1.5. In the roll-off (q < q_r) the conversion is coarse
(rms error a factor 1.3–1.8); the top ~quarter decade below q_Ny is biased by the missing
roughness beyond q_Ny. ``psd.h_rms`` exceeds the profiles' rms — a profile misses the
roughness with wavevector perpendicular to it (qx = 0 is removed with each scan's mean), the
2-D spectrum does not — by -0.3 … +5.5 % for a roll-off at 16–32·q_lo and up to +10 % at
8·q_lo (all rows of a map; one scan: +3 … +24 %); it matches the areal rms of the map to
≤ 4.3 % (roll-off at 16·q_lo).
"""
from __future__ import annotations

import math
import os
import uuid
import warnings
from pathlib import Path

import numpy as np
from scipy.special import betainc, beta as beta_fn, gammaln

from .._core.validate import as_float_array, check_positive
from .psd import CONVENTIONS, PSD, TabulatedPSD

__all__ = ["psd_from_heights", "line_psd", "line_scans", "read_psd", "write_psd",
           "synthetic_heights", "abel_forward", "abel_invert", "abel_fit",
           "CONVENTION_KEY", "BINS_PER_DECADE"]

#: Parquet key-value metadata key holding the convention of the stored C column
CONVENTION_KEY = b"fastcontact.convention"
#: default number of log-spaced bins per decade of q
BINS_PER_DECADE = 10
_MIN_SAMPLES = 8
_WINDOWS = (None, "hann")
_DETRENDS = ("mean", "plane")
_GL_X, _GL_W = np.polynomial.legendre.leggauss(8)
#: prior std of the change of log-log slope between neighbouring C1D nodes (line scans)
ABEL_SLOPE_PRIOR = 1.0
#: bins whose mean periodogram is below this fraction of the largest are FFT round-off
ROUNDOFF_FLOOR = 1e-24
#: |psd.h_rms / rms(heights) - 1| above which psd_from_heights warns (2-D maps, no window)
PARSEVAL_WARN = 0.01


# ============================================================================ validation
def _check_heights(heights, *, allow_1d=True, scans=False):
    h = as_float_array("heights", heights)
    if h.ndim not in ((1, 2) if allow_1d else (2,)):
        want = "a 1-D line scan or a 2-D map" if allow_1d else "a 2-D map"
        raise ValueError(f"heights has shape {h.shape} (ndim = {h.ndim}) is invalid: "
                         f"must be {want}")
    if (h.shape[-1] if scans else min(h.shape)) < _MIN_SAMPLES:
        where = "per scan (rows are scans)" if scans else "in every dimension"
        raise ValueError(f"heights has shape {h.shape} is invalid: must have at least "
                         f"{_MIN_SAMPLES} samples {where}")
    if not np.all(np.isfinite(h)):
        idx = tuple(int(i) for i in np.argwhere(~np.isfinite(h))[0])
        raise ValueError(f"heights = {float(h[idx])!r} at index {idx} is invalid: every height "
                         f"must be finite [m] (no NaN / inf; fill or crop missing data first)")
    return h


def _check_spacing(spacing):
    s = check_positive("spacing", spacing, "[m]")
    if s.ndim != 0:
        raise ValueError(f"spacing = {spacing!r} is invalid: must be a single number > 0 [m] "
                         f"(square grid)")
    return float(s)


def _check_choice(name, value, choices):
    if value not in choices:
        raise ValueError(f"{name} = {value!r} is invalid: must be one of {list(choices)}")
    return value


def _check_n_bins(n_bins):
    if n_bins is None:
        return None
    if isinstance(n_bins, bool) or not isinstance(n_bins, (int, np.integer)) or n_bins < 2:
        raise ValueError(f"n_bins = {n_bins!r} is invalid: must be None or an integer >= 2")
    return int(n_bins)


def _check_convention(convention):
    if convention is None or not isinstance(convention, str) or convention not in CONVENTIONS:
        raise ValueError(
            f"convention = {convention!r} is invalid: must be one of {sorted(CONVENTIONS)} "
            f"and is required (\"persson\": C = (2π)^-2 ∫<hh>e^-iqx, h_rms² = 2π∫qC dq; "
            f"\"surface_topography\" / contact.engineering: (2π)² times Persson's C)")
    return convention


# ============================================================================ helpers
def line_scans(heights, axis=0):
    """The profiles of a 2-D height map that run along ``axis``, one per row.

    ``axis=0``: each column of ``heights`` (a profile along the first index) becomes a row;
    ``axis=1``: the rows themselves. A 1-D array is returned as a single row. The result is a
    C-contiguous 2-D array, as :func:`psd_from_heights` (``line_scans=True``) expects.
    """
    h = as_float_array("heights", heights)
    if h.ndim == 1:
        return h[None, :].copy()
    if h.ndim != 2:
        raise ValueError(f"heights has shape {h.shape} is invalid: must be 1-D or 2-D")
    if axis not in (0, 1, -1, -2):
        raise ValueError(f"axis = {axis!r} is invalid: must be 0 or 1")
    return np.array(np.moveaxis(h, axis, -1), order="C", copy=True)


def _detrend_rows(h, detrend):
    """Remove each row's mean, or least-squares straight line (detrend='plane')."""
    h = h - h.mean(axis=-1, keepdims=True)
    if detrend == "plane":
        x = np.arange(h.shape[-1], dtype=np.float64)
        x -= x.mean()
        slope = (h @ x) / (x @ x)
        h = h - slope[:, None] * x[None, :]
    return h


def _detrend_map(h, detrend):
    """Remove the mean, or the least-squares plane (detrend='plane'), of a 2-D map."""
    h = h - h.mean()
    if detrend == "plane":
        y = np.arange(h.shape[0], dtype=np.float64)
        x = np.arange(h.shape[1], dtype=np.float64)
        y -= y.mean()
        x -= x.mean()
        gy = (h.sum(axis=1) @ y) / (h.shape[1] * (y @ y))
        gx = (h.sum(axis=0) @ x) / (h.shape[0] * (x @ x))
        h = h - gy * y[:, None] - gx * x[None, :]
    return h


def _hann(n):
    """Symmetric Hann window normalised to mean(w²) = 1 (variance-preserving on average)."""
    w = np.hanning(n)
    return w / math.sqrt(np.mean(w * w))


def _default_n_bins(q_lo, q_hi):
    return max(4, int(math.ceil(BINS_PER_DECADE * math.log10(q_hi / q_lo))))


def _bin_edges(q_lo, q_hi, n_bins, dq=None):
    """Log-spaced bin edges on [q_lo, q_hi]; with ``dq`` (1-D lattice k·dq) the inner edges are
    snapped to half-integer multiples of dq, so every bin holds whole lattice cells."""
    edges = np.geomspace(q_lo, q_hi, n_bins + 1)
    if dq is not None:
        inner = (np.round(edges[1:-1] / dq - 0.5) + 0.5) * dq
        inner = inner[(inner > q_lo) & (inner < q_hi)]
        edges = np.unique(np.concatenate(([q_lo], inner, [q_hi])))
    return edges


EQUAL_AREA_MAX_CELLS = 200


def _equal_area_edges(edges, qk, cell):
    """Bin edges moved to equal-area radii: each edge e becomes √(N(e)·cell/π), N(e) the
    number of lattice points (origin included) with |q| < e."""
    qs = np.sort(qk)
    n_in = np.searchsorted(qs, edges, side="left")
    moved = np.sqrt(np.maximum(n_in, 1) * cell / math.pi)
    # only where the lattice is coarse (few cells inside): further out the disc area and the
    # cell count agree to a fraction of a percent and the log-spaced edges are kept
    out = np.where(n_in < EQUAL_AREA_MAX_CELLS, moved, edges)
    out[0] = math.sqrt(cell / math.pi)
    return np.unique(out)


def _tile_bins(qk, vk, edges):
    """Mean of the samples ``vk`` (at wavevectors ``qk``) in each bin of ``edges``.

    Samples outside [edges[0], edges[-1]] are ignored; an empty bin is merged into the next
    non-empty one (the last into the previous), so the returned bins still tile the band.
    Returns (edges, mean, count).
    """
    q_lo, q_hi = edges[0], edges[-1]
    tol = 1e-9
    inb = (qk >= q_lo * (1 - tol)) & (qk <= q_hi * (1 + tol))
    qk, vk = qk[inb], vk[inb]
    nb = edges.size - 1
    idx = np.clip(np.searchsorted(edges, qk * (1 + 1e-12), side="right") - 1, 0, nb - 1)
    cnt = np.bincount(idx, minlength=nb)
    ne = np.flatnonzero(cnt > 0)
    if ne.size == 0:
        return edges[[0, -1]], np.zeros(1), np.zeros(1)
    new = np.concatenate(([q_lo], edges[ne[:-1] + 1], [q_hi]))
    idx = np.clip(np.searchsorted(new, qk * (1 + 1e-12), side="right") - 1, 0, new.size - 2)
    cnt = np.bincount(idx, minlength=new.size - 1).astype(np.float64)
    vsum = np.bincount(idx, weights=vk, minlength=new.size - 1)
    return new, vsum / cnt, cnt


def _trim_roundoff(edges, mean, cnt):
    """Drop the bins at either end of the band whose mean is at FFT round-off level
    (< :data:`ROUNDOFF_FLOOR` × the largest), e.g. above q1 or below q0 of a synthetic map."""
    ok = np.flatnonzero(mean > ROUNDOFF_FLOOR * np.max(mean))
    i, j = int(ok[0]), int(ok[-1])
    return edges[i:j + 2], mean[i:j + 1], cnt[i:j + 1]


def _table_nodes(qc, v, q_lo, q_hi):
    """Table through (qc, v), extended flat to q_lo and as the last segment's power law to q_hi."""
    if v.size >= 2:
        s = math.log(v[-1] / v[-2]) / math.log(qc[-1] / qc[-2])
    else:
        s = 0.0
    q = np.concatenate(([q_lo], qc, [q_hi]))
    c = np.concatenate(([v[0]], v, [v[-1] * (q_hi / qc[-1]) ** s]))
    return q, c


def _pl_integral(c, qs, e, n, a, b):
    """∫_a^b q^n c (q/qs)^e dq, elementwise over arrays (cancellation-free, as psd.py)."""
    k = n + e + 1.0
    lr = np.log(b / a)
    pref = c * (a / qs) ** e * a ** (n + 1.0)
    small = np.abs(k * lr) < 1e-12
    ks = np.where(small, 1.0, k)
    return pref * np.where(small, lr, np.expm1(ks * lr) / ks)


def _histopolate(edges, mean, dim, maxit=1000, rtol=1e-12):
    """Area-preserving ("histopolating") log-log table of a bin-averaged spectrum.

    Finds values at the geometric bin centres such that the log-log linear interpolant (ends
    extended by :func:`_table_nodes`) integrates over every bin to ``mean × measure`` — the
    measure being the annulus area π(e₊²-e₋²) for ``dim=2`` (C, energy 2π∫qC dq) or the length
    2(e₊-e₋) for ``dim=1`` (C1D, energy 2∫C1D dq). A local power law is reproduced exactly
    (no bin-width bias), the energy of every bin is kept (Parseval), and a sharp kink such as
    a roll-off is not rounded off (a plain interpolant through bin means loses ~1.5 % of the
    variance at a roll-off with 10 bins per decade). Multiplicative fixed-point iteration
    (values stay positive). Returns the table nodes (q, value), ends at edges[0], edges[-1].
    """
    qc = np.sqrt(edges[:-1] * edges[1:])
    q_lo, q_hi = float(edges[0]), float(edges[-1])
    if dim == 2:
        meas, n, f = math.pi * (edges[1:] ** 2 - edges[:-1] ** 2), 1.0, 2.0 * math.pi
    else:
        meas, n, f = 2.0 * (edges[1:] - edges[:-1]), 0.0, 2.0
    floor = np.max(mean) * 1e-30
    mean = np.maximum(mean, floor)
    target = mean * meas
    v = mean.copy()
    if v.size == 1:
        return np.array([q_lo, q_hi]), np.array([v[0], v[0]])
    lo, hi = edges[:-1], edges[1:]
    for _ in range(maxit):
        q, c = _table_nodes(qc, v, q_lo, q_hi)
        e = np.log(c[1:] / c[:-1]) / np.log(q[1:] / q[:-1])        # slope of segment j
        # bin i = [lo_i, qc_i] (segment i) + [qc_i, hi_i] (segment i+1)
        left = _pl_integral(c[:-2], q[:-2], e[:-1], n, lo, qc)
        right = _pl_integral(c[1:-1], q[1:-1], e[1:], n, qc, hi)
        r = target / (f * (left + right))
        if np.max(np.abs(r - 1.0)) < rtol:
            break
        v = np.maximum(v * r, floor)
    return _table_nodes(qc, v, q_lo, q_hi)


# ============================================================================ 1-D spectra
def _line_periodogram(rows, spacing, window, detrend):
    """Row-averaged one-sided C1D(q_k) for k = 1 .. M//2 (SPEC §1 normalisation).

    Returns (q_k, C1D_k, w_k, h2) with w_k the Parseval weight of each sample
    (2 for 0 < k < M/2, 1 for the Nyquist term of even M) so that
    ``h2 = mean(h²) = Σ_k w_k C1D_k Δq``.
    """
    rows = _detrend_rows(rows, detrend)
    h2 = float(np.mean(rows * rows))
    m = rows.shape[-1]
    if window == "hann":
        rows = rows * _hann(m)[None, :]
    Z = np.fft.rfft(rows, axis=-1)[:, 1:]
    c1 = spacing * np.mean(np.abs(Z) ** 2, axis=0) / (2.0 * math.pi * m)
    k = np.arange(1, m // 2 + 1)
    q = 2.0 * math.pi * k / (m * spacing)
    w = np.full(k.size, 2.0)
    if m % 2 == 0:
        w[-1] = 1.0
    return q, c1, w, h2


def _spectrum_1d(rows, spacing, n_bins, window, detrend):
    """Row-averaged C1D as an area-preserving log-log table on [2π/L, π/a].

    Returns (q nodes, C1D nodes, statistical weight of each node, mean(h²) of the detrended
    rows). The weight is the number of periodogram values in the node's bin times an
    effective number of independent scans, min(R, q/q_lo): R scans taken from one map are
    strongly correlated at long wavelengths (exactly so at q_lo), independent ones are
    under-weighted by this (conservative: slightly more smoothing, see :func:`abel_fit`).
    """
    qk, c1, _, h2 = _line_periodogram(rows, spacing, window, detrend)
    q_lo, q_hi, dq = float(qk[0]), math.pi / spacing, float(qk[0])
    nb = _default_n_bins(q_lo, q_hi) if n_bins is None else n_bins
    edges, mean, cnt = _tile_bins(qk, c1, _bin_edges(q_lo, q_hi, nb, dq=dq))
    if not np.any(mean > 0):
        raise ValueError("heights = constant (after detrending) is invalid: the surface must "
                         "have roughness (nonzero spectrum)")
    edges, mean, cnt = _trim_roundoff(edges, mean, cnt)
    q, d = _histopolate(edges, mean, dim=1)
    cnt = np.concatenate((cnt[:1], cnt, cnt[-1:]))
    w = cnt * np.minimum(rows.shape[0], np.maximum(1.0, q / q_lo))
    w[0] = w[-1] = 0.0          # end nodes are extrapolations, not data
    return q, d, w, h2


def line_psd(heights, spacing, *, n_bins=None, window=None, detrend="mean", axis=-1):
    """The 1-D spectrum C1D(q) [m³] of a line scan, or the average over many scans.

    ``heights``: 1-D profile, or 2-D array whose profiles run along ``axis`` (default -1:
    each row is a scan). Returns ``(q [1/m], C1D [m³])``, the nodes of the area-preserving
    log-log table (see :func:`_histopolate`) on [2π/L, π/a], with
    ``h_rms² = 2∫ C1D dq`` (SPEC §1). ``n_bins``, ``window``, ``detrend`` as in
    :func:`psd_from_heights`.
    """
    rows = _check_heights(line_scans(heights, axis=axis), scans=True)
    spacing = _check_spacing(spacing)
    n_bins = _check_n_bins(n_bins)
    _check_choice("window", window, _WINDOWS)
    _check_choice("detrend", detrend, _DETRENDS)
    q, d, _, _ = _spectrum_1d(rows, spacing, n_bins, window, detrend)
    return q, d


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
    """Γ(1+H)/(√π Γ(H+½)): C = factor · C1D/q for C1D ∝ q^{-(1+2H)} (SPEC §1)."""
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


# ============================================================================ public API
def psd_from_heights(heights, spacing, *, n_bins=None, window=None, line_scans=False,
                     detrend="mean"):
    """The isotropic Persson-convention spectrum C(q) of measured or synthetic heights.

    Parameters
    ----------
    heights : array [m]
        2-D N×M height map (treated as periodic), or a 1-D line scan, or — with
        ``line_scans=True`` — a 2-D array whose rows are independent line scans of the same
        isotropic surface (their 1-D spectra are averaged). Finite, at least 8 samples per
        dimension.
    spacing : float [m]
        Grid spacing a, > 0 (the same along both axes of a map).
    n_bins : int, optional
        Number of log-spaced bins between q_lo = 2π/L and q_Ny = π/a
        (default: 10 per decade). An empty bin is merged into its neighbour.
    window : None or "hann"
        None (default) assumes periodic data (Parseval holds). "hann" multiplies by
        a (separable) Hann window normalised to mean(w²) = 1, reducing leakage for
        non-periodic measurements; Parseval then holds only on average.
    line_scans : bool
        Treat the rows of a 2-D array as line scans (see above). A 1-D array always is one.
    detrend : "mean" (default) or "plane"
        Subtracted before the FFT: the mean, or the least-squares plane of a map (for line
        scans: each scan's mean, or its least-squares straight line). Parseval refers to the
        detrended heights.

    Returns
    -------
    TabulatedPSD in the Persson convention [m^4] on [q_lo, q_Ny].

    Accuracy (details and measurements in the module doc)
    --------
    2-D map: ``psd.h_rms`` equals the rms of the detrended heights to ≤ 0.25 % (roll-off at
    ≥ 16·q_lo) / ≤ 1 % (8·q_lo); energy beyond q_Ny (FFT corners) is not represented; a
    RuntimeWarning is issued above 1 %. Line scans: the regularised Abel fit recovers C in
    the self-affine band to ~4 % rms from many scans (~16 % rms from one scan); ``psd.h_rms``
    exceeds the profiles' rms by up to ~5 % (roll-off ≥ 16·q_lo; ~10 % at 8·q_lo): they miss
    the roughness perpendicular to them.
    """
    if not isinstance(line_scans, (bool, np.bool_)):
        raise ValueError(f"line_scans = {line_scans!r} is invalid: must be True or False")
    h = _check_heights(heights, scans=bool(line_scans))
    spacing = _check_spacing(spacing)
    n_bins = _check_n_bins(n_bins)
    _check_choice("window", window, _WINDOWS)
    _check_choice("detrend", detrend, _DETRENDS)
    if h.ndim == 1 or line_scans:
        rows = h[None, :] if h.ndim == 1 else h
        q, d, w, _ = _spectrum_1d(rows, spacing, n_bins, window, detrend)
        C = abel_fit(q, d, w)
        return TabulatedPSD(q, C, convention="persson")

    # ---- 2-D periodic map
    h = _detrend_map(h, detrend)
    ny, nx = h.shape
    if window == "hann":
        h = h * _hann(ny)[:, None] * _hann(nx)[None, :]
    h2 = float(np.mean(h * h))
    if not h2 > 0:
        raise ValueError("heights = constant (after detrending) is invalid: the surface must "
                         "have roughness (nonzero spectrum)")
    Z = np.fft.fft2(h)
    Ck = (spacing ** 2 / ((2.0 * math.pi) ** 2 * nx * ny)) * (Z.real ** 2 + Z.imag ** 2)
    qy = 2.0 * math.pi * np.fft.fftfreq(ny, spacing)
    qx = 2.0 * math.pi * np.fft.fftfreq(nx, spacing)
    qk = np.hypot(qy[:, None], qx[None, :]).ravel()
    dqx, dqy = 2.0 * math.pi / (nx * spacing), 2.0 * math.pi / (ny * spacing)
    # log-spaced bins from 2π/L (L the longest side) to the Nyquist wavevector; near the
    # origin, where the lattice is coarse, the edges move to equal-area radii and the band
    # starts at the equal-area radius of the origin's cell (see _equal_area_edges)
    q_lo, q_hi = 2.0 * math.pi / (max(nx, ny) * spacing), math.pi / spacing
    nb = _default_n_bins(q_lo, q_hi) if n_bins is None else n_bins
    edges = _equal_area_edges(_bin_edges(q_lo, q_hi, nb), qk, dqx * dqy)
    q_lo = edges[0]
    edges, mean, _ = _tile_bins(qk, Ck.ravel(), edges)
    if not np.any(mean > 0):
        raise ValueError(f"heights is invalid: must have roughness between q_lo = {q_lo:.4g} and "
                         f"the Nyquist wavevector {q_hi:.4g} [1/m] (all of it is in the FFT "
                         f"corners)")
    edges, mean, _ = _trim_roundoff(edges, mean, np.zeros(mean.size))
    q, C = _histopolate(edges, mean, dim=2)
    psd = TabulatedPSD(q, C, convention="persson")
    if window is None:
        dev = psd.h_rms / math.sqrt(h2) - 1.0
        if abs(dev) > PARSEVAL_WARN:
            warnings.warn(
                f"psd_from_heights: the spectrum's h_rms = {psd.h_rms:.4g} m differs from the "
                f"heights' rms {math.sqrt(h2):.4g} m by {100 * dev:+.2f} %: the map does not "
                f"resolve its longest wavelengths (roll-off below ~10·2π/L, the lattice sum over "
                f"the few lowest wavevectors is not the integral of C) or has roughness beyond the "
                f"Nyquist wavevector π/a (FFT corners)", RuntimeWarning, stacklevel=2)
    return psd


def synthetic_heights(psd, n, spacing, seed=None, *, random_amplitudes=True):
    """A random periodic n×n height map [m] whose expected spectrum is ``psd``.

    Fourier filtering (SPEC §1 normalisation): ``Z_k = (2π/a) √C(|q_k|) · W_k`` with ``W`` the
    FFT of unit white noise — random phases with the Hermitian symmetry that makes the map
    real, and Rayleigh amplitudes (a Gaussian random surface, the default); with
    ``random_amplitudes=False``, ``|W_k| = n`` exactly (random phases only, the periodogram
    equals C at every lattice point). ``Z_0 = 0`` (zero mean). Then
    ``E[mean(h²)] = Σ_{k≠0} C(q_k) Δq²``, Δq = 2π/(n a): this equals ``psd.h_rms²`` when the
    map resolves the spectrum (q0 ≳ 2π/(n a), q1 ≤ π/a, several lattice points below the
    roll-off); roughness outside the lattice is simply absent.

    Parameters: ``psd`` a fastcontact PSD, ``n`` (int ≥ 8) samples per side, ``spacing``
    [m] > 0, ``seed`` anything ``numpy.random.default_rng`` accepts.
    """
    if not isinstance(psd, PSD):
        raise ValueError(f"psd = {psd!r} is invalid: must be a fastcontact PSD object")
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < _MIN_SAMPLES:
        raise ValueError(f"n = {n!r} is invalid: must be an integer >= {_MIN_SAMPLES}")
    n = int(n)
    spacing = _check_spacing(spacing)
    rng = np.random.default_rng(seed)
    W = np.fft.fft2(rng.standard_normal((n, n)))
    if not random_amplitudes:
        W = n * W / np.maximum(np.abs(W), 1e-300)
    q1d = 2.0 * math.pi * np.fft.fftfreq(n, spacing)
    qk = np.hypot(q1d[:, None], q1d[None, :])
    # a lattice point that is q0 or q1 up to round-off (e.g. q0 = 2π/(n a)) belongs to the PSD
    for edge in (psd.q0, psd.q1):
        qk[np.abs(qk / edge - 1.0) < 1e-9] = edge
    filt = (2.0 * math.pi / spacing) * np.sqrt(psd(qk))
    filt[0, 0] = 0.0
    return np.fft.ifft2(W * filt).real


# ============================================================================ files
def _kind(path):
    name = Path(path).name.lower()
    if name.endswith(".csv"):
        return "csv"
    if name.endswith(".csv.gz"):
        return "csv.gz"
    if name.endswith((".parquet", ".pq")):
        return "parquet"
    raise ValueError(f"path = {str(path)!r} is invalid: must end in .csv, .csv.gz, .parquet "
                     f"or .pq")


def read_psd(path, convention=None, *, q_col=None, C_col=None):
    """Read a tabulated spectrum file into a :class:`TabulatedPSD` (Persson convention).

    Parameters
    ----------
    path : str or Path
        ``.csv`` (header row, then one sample per line) or ``.parquet`` / ``.pq``.
        q in [1/m] (strictly increasing, > 0), C in [m^4] (> 0), SI units.
    convention : "persson" or "surface_topography"
        **Required**: the normalisation of the file's C column (contact.engineering exports
        are "surface_topography", i.e. (2π)² times Persson's C). A Parquet file may carry
        its convention in the key-value metadata ``fastcontact.convention``; it must then
        equal ``convention``.
    q_col, C_col : str, optional
        Column names (default "q" and "C").

    Files are parsed as plain data (pandas CSV reader / pyarrow); nothing is unpickled or
    evaluated.
    """
    convention = _check_convention(convention)
    q_col = "q" if q_col is None else q_col
    C_col = "C" if C_col is None else C_col
    for nm, v in (("q_col", q_col), ("C_col", C_col)):
        if not isinstance(v, str) or not v:
            raise ValueError(f"{nm} = {v!r} is invalid: must be a non-empty column name")
    path = os.fspath(path)
    kind = _kind(path)
    if not os.path.isfile(path):
        raise ValueError(f"path = {path!r} is invalid: no such file")
    if kind in ("csv", "csv.gz"):
        import pandas as pd
        try:
            df = pd.read_csv(path, comment="#", skipinitialspace=True,
                             compression="gzip" if kind == "csv.gz" else None)
        except Exception as exc:  # malformed text, empty file, ...
            raise ValueError(f"path = {path!r} is invalid: cannot parse as CSV ({exc})") from None
        df.columns = [str(c).strip() for c in df.columns]
        columns = list(df.columns)
        get = lambda name: df[name].to_numpy()  # noqa: E731
    else:
        import pyarrow.parquet as pq
        try:
            table = pq.read_table(path)
        except Exception as exc:
            raise ValueError(f"path = {path!r} is invalid: cannot read as Parquet "
                             f"({exc})") from None
        meta = table.schema.metadata or {}
        stored = meta.get(CONVENTION_KEY)
        if stored is not None:
            stored = stored.decode("utf-8", "replace")
            if stored != convention:
                raise ValueError(
                    f"convention = {convention!r} is invalid for {path!r}: the file's metadata "
                    f"{CONVENTION_KEY.decode()} says {stored!r}; pass convention={stored!r}")
        columns = list(table.column_names)
        get = lambda name: table.column(name).to_numpy(zero_copy_only=False)  # noqa: E731
    for nm, col in (("q_col", q_col), ("C_col", C_col)):
        if col not in columns:
            raise ValueError(f"{nm} = {col!r} is invalid for {path!r}: no such column "
                             f"(columns: {columns})")
    out = []
    for nm, col in (("q", q_col), ("C", C_col)):
        raw = get(col)
        try:
            arr = np.asarray(raw, dtype=np.float64)
        except (TypeError, ValueError):
            raise ValueError(f"{nm} = column {col!r} of {path!r} is invalid: must hold numbers "
                             f"only") from None
        out.append(arr)
    try:
        return TabulatedPSD(out[0], out[1], convention=convention)
    except ValueError as exc:
        raise ValueError(f"{exc} (column {q_col!r}/{C_col!r} of {path!r})") from None


def _samples(psd):
    """(q, C_persson) samples whose log-log interpolant is exactly ``psd``."""
    if isinstance(psd, TabulatedPSD):
        return psd.q_samples.copy(), psd.C_samples.copy()
    qb, c, e = psd.qb, psd.c, psd.e
    end = c * (qb[1:] / qb[:-1]) ** e                  # C at the right end of each segment
    jump = np.abs(end[:-1] / c[1:] - 1.0)
    if np.any(jump > 1e-9):
        i = int(np.argmax(jump > 1e-9))
        raise ValueError(f"psd = {psd!r} is invalid for a table: C jumps at q = {qb[i + 1]!r} "
                         f"[1/m], which log-log interpolated samples cannot represent")
    return qb.copy(), np.concatenate((c, end[-1:]))


def write_psd(psd, path, convention="persson"):
    """Write ``psd`` as a table of samples (CSV or Parquet, by the suffix of ``path``).

    The samples are the spectrum's tabulated points (a :class:`TabulatedPSD`) or its power-law
    breakpoints (e.g. :class:`SelfAffinePSD`: q0, q_roll, q1), so that :func:`read_psd`
    reproduces it exactly (to float round-off). C is written in ``convention``; Parquet
    files also record it in the metadata key ``fastcontact.convention``. CSV: header
    ``q,C``, 17 significant digits. The file is written to a temporary name in the same folder
    and then atomically renamed over ``path``.
    """
    if not isinstance(psd, PSD):
        raise ValueError(f"psd = {psd!r} is invalid: must be a fastcontact PSD object")
    convention = _check_convention(convention)
    path = os.fspath(path)
    kind = _kind(path)
    q, C = _samples(psd)
    C = C / CONVENTIONS[convention]
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        raise ValueError(f"path = {path!r} is invalid: folder {folder!r} does not exist")
    tmp = os.path.join(folder, f".{os.path.basename(path)}.{os.getpid()}.{uuid.uuid4().hex}.tmp")
    try:
        if kind in ("csv", "csv.gz"):
            import pandas as pd
            pd.DataFrame({"q": q, "C": C}).to_csv(
                tmp, index=False, float_format="%.17g",
                compression="gzip" if kind == "csv.gz" else None)
        else:
            import pyarrow as pa
            import pyarrow.parquet as pq
            table = pa.table({"q": pa.array(q, pa.float64()), "C": pa.array(C, pa.float64())})
            table = table.replace_schema_metadata({
                CONVENTION_KEY: convention.encode(),
                b"fastcontact.units": b"q [1/m], C [m^4]",
            })
            pq.write_table(table, tmp)
        with open(tmp, "rb+") as fh:
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise
    return path
