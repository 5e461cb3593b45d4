"""Surface topography → power spectrum C(q), spectrum files, synthetic surfaces (SPEC §1).

Glossary
--------
h(x)        surface heights [m] on a regular grid of ``spacing`` a [m]
N, M        map size: ``heights.shape == (N, M)`` (rows, columns); a line scan has M samples
L           scan length, L = M a (a map's longest side sets q_lo) [m]
q_lo        smallest wavevector of the returned spectrum, 2π/L [1/m]
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

Radial averaging (2-D maps)
---------------------------
The periodogram is averaged over the lattice points of log-spaced annuli between q_lo and
q_Ny (q = 0 dropped, points beyond q_Ny — the corners of the FFT square — dropped, empty bins
dropped). The abscissa of each bin is not its centre but the *power-law-consistent* point
``q_i = <q^p>^{1/p}`` over the bin's lattice points, with p the local log-log slope of the
binned spectrum: the log-log interpolant through (q_i, C_i) then reproduces a local power law
exactly, so neither the shape nor the bin energy is biased by the bin width (plain bin
centres bias a q^-3.6 spectrum by ~2 % per bin, which would break Parseval at the 1 % level).
The first/last samples are moved to q_lo/q_Ny (constant / local-slope extrapolation) so the
table covers the whole measured band.

Line scans → isotropic 2-D C(q)
-------------------------------
For isotropic roughness the 1-D spectrum of any straight profile is the Abel-type projection
``C1D(qx) = ∫ dqy C(√(qx²+qy²)) = 2 ∫_{qx}^∞ C(q) q dq / √(q²-qx²)``, inverted as::

    C(q) = -(1/π) ∫_q^∞ C1D'(k) dk / √(k²-q²) = -(1/π) ∫_0^∞ C1D'(q cosh t) dt .

C1D is first log-binned (as above, 1-D lattice) and represented by the log-log linear
interpolant of the bins, which is a piecewise power law, so ``C1D'(k) = s C1D(k)/k`` with s the
segment's slope. Each segment is integrated by 8-point Gauss–Legendre in t (the substitution
removes the inverse-square-root singularity; the integrand is smooth inside a segment); above
the last bin C1D is continued as a power law (slope fitted to the top ~0.15 decade, capped at
-1 so it is integrable) whose contribution is the closed form
``(q^{s-1}/2) B(q²/k²; (1-s)/2, ½)`` (incomplete beta). For a pure power law this is exactly
SPEC's ``C = Γ(1+H)/(√π Γ(H+½)) C1D/q``, but unlike that factor (or a per-decade local-H
version of it) it stays correct through the roll-off and other curvature of the spectrum,
and it needs no derivative of noisy data (only the slopes of averaged bins, then integrated).
If noise makes the inversion non-positive at some sample (a rising C1D segment), that sample
falls back to the local power-law factor with H from a ±0.25-decade least-squares fit,
clipped to [0, 1]. Measured accuracy: see ``tests/test_topography.py`` and the function doc.
"""
from __future__ import annotations

import math
import os
import tempfile
from pathlib import Path

import numpy as np
from scipy.special import betainc, beta as beta_fn, gammaln

from ._validate import as_float_array, check_positive
from .psd import CONVENTIONS, PSD, TabulatedPSD

__all__ = ["psd_from_heights", "line_psd", "line_scans", "read_psd", "write_psd",
           "synthetic_heights", "CONVENTION_KEY", "BINS_PER_DECADE"]

#: Parquet key-value metadata key holding the convention of the stored C column
CONVENTION_KEY = b"fastcontact.convention"
#: default number of log-spaced bins per decade of q
BINS_PER_DECADE = 10
_MIN_SAMPLES = 8
_WINDOWS = (None, "hann")
_DETRENDS = ("mean", "plane")
_GL_X, _GL_W = np.polynomial.legendre.leggauss(8)


# ============================================================================ validation
def _check_heights(heights, *, allow_1d=True):
    h = as_float_array("heights", heights)
    if h.ndim not in ((1, 2) if allow_1d else (2,)):
        want = "a 1-D line scan or a 2-D map" if allow_1d else "a 2-D map"
        raise ValueError(f"heights has shape {h.shape} (ndim = {h.ndim}) is invalid: must be {want}")
    if min(h.shape) < _MIN_SAMPLES:
        raise ValueError(f"heights has shape {h.shape} is invalid: must have at least "
                         f"{_MIN_SAMPLES} samples in every dimension")
    if not np.all(np.isfinite(h)):
        idx = tuple(int(i) for i in np.argwhere(~np.isfinite(h))[0])
        raise ValueError(f"heights = {h[idx]!r} at index {idx} is invalid: every height must be "
                         f"finite [m] (no NaN / inf; fill or crop missing data first)")
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
    return np.ascontiguousarray(np.moveaxis(h, axis, -1))


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


def _log_bin(qk, vk, q_lo, q_hi, n_bins, dim):
    """Average the samples ``vk`` at wavevectors ``qk`` in log bins on [q_lo, q_hi].

    Returns (q_i, v_i, count_i) for the non-empty bins with v_i > 0. ``dim`` (1 or 2) is the
    dimension of the lattice: it only enters the power-law-consistent abscissa
    ``q_i = <q^p>^{1/p}`` (the mean over the bin's lattice points, which already carry the
    right density q^{dim-1}).
    """
    edges = np.geomspace(q_lo, q_hi, n_bins + 1)
    edges[0] = q_lo * (1.0 - 1e-9)
    edges[-1] = q_hi * (1.0 + 1e-9)
    inb = (qk >= edges[0]) & (qk <= edges[-1])
    qk, vk = qk[inb], vk[inb]
    idx = np.clip(np.searchsorted(edges, qk, side="right") - 1, 0, n_bins - 1)
    cnt = np.bincount(idx, minlength=n_bins).astype(np.float64)
    vsum = np.bincount(idx, weights=vk, minlength=n_bins)
    lsum = np.bincount(idx, weights=np.log(qk), minlength=n_bins)
    keep = cnt > 0
    v = np.zeros(n_bins)
    v[keep] = vsum[keep] / cnt[keep]
    keep &= v > 0
    lq = np.full(n_bins, np.nan)
    lq[keep] = lsum[keep] / cnt[keep]            # geometric-mean abscissa (first pass)
    kb = np.flatnonzero(keep)
    if kb.size >= 3:
        # local log-log slope p of the binned spectrum, then q_i = <q^p>^{1/p}
        lv = np.log(v[kb])
        p = np.gradient(lv, lq[kb])
        p = np.clip(p, -12.0, 12.0)
        pk = np.zeros(n_bins)
        pk[kb] = p
        pp = pk[idx]
        lqk = np.log(qk)
        lq0 = lq[idx]                             # centre the exponent for conditioning
        ok = keep[idx]
        mom = np.bincount(idx[ok], weights=np.exp(pp[ok] * (lqk[ok] - lq0[ok])), minlength=n_bins)
        with np.errstate(divide="ignore", invalid="ignore"):
            corr = np.where(np.abs(pk) > 1e-8, np.log(mom / np.maximum(cnt, 1.0)) / pk, 0.0)
        lq[kb] = lq[kb] + corr[kb]
    return np.exp(lq[kb]), v[kb], cnt[kb]


def _extend_to_band(q, v, q_lo, q_hi):
    """Move the table's end points to the band edges: flat below, local power law above."""
    q = q.copy()
    v = v.copy()
    if q[0] > q_lo * (1 + 1e-12):
        q = np.concatenate(([q_lo], q))
        v = np.concatenate(([v[0]], v))
    if q[-1] < q_hi * (1 - 1e-12):
        if q.size >= 2:
            s = math.log(v[-1] / v[-2]) / math.log(q[-1] / q[-2])
        else:
            s = 0.0
        v = np.concatenate((v, [v[-1] * (q_hi / q[-1]) ** s]))
        q = np.concatenate((q, [q_hi]))
    return q, v


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


def line_psd(heights, spacing, *, n_bins=None, window=None, detrend="mean", axis=-1):
    """The 1-D spectrum C1D(q) [m³] of a line scan, or the average over many, log-binned.

    ``heights``: 1-D profile, or 2-D array whose profiles run along ``axis`` (default: each
    row is a scan). Returns ``(q [1/m], C1D [m³])`` with ``h_rms² = 2∫_0^∞ C1D dq``
    (SPEC §1), between q_lo = 2π/L and q_Ny = π/a.
    """
    h = _check_heights(heights)
    spacing = _check_spacing(spacing)
    n_bins = _check_n_bins(n_bins)
    _check_choice("window", window, _WINDOWS)
    _check_choice("detrend", detrend, _DETRENDS)
    rows = h[None, :] if h.ndim == 1 else line_scans(h, axis=axis)
    q, c1, _, _ = _line_periodogram(rows, spacing, window, detrend)
    q_lo, q_hi = q[0], math.pi / spacing
    nb = _default_n_bins(q_lo, q_hi) if n_bins is None else n_bins
    qb, cb, _ = _log_bin(q, c1, q_lo, q_hi, nb, dim=1)
    if qb.size < 2:
        raise ValueError("heights has (almost) no roughness: fewer than 2 spectrum bins are > 0")
    return qb, cb


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


def abel_invert(q, c1d):
    """Isotropic 2-D C(q) [m^4] at the samples ``q`` from a sampled 1-D spectrum C1D [m³].

    Inverts ``C1D(qx) = ∫ dqy C(√(qx²+qy²))`` for the log-log linear interpolant of the samples
    continued above ``q[-1]`` by a power law (see the module doc). Returns ``(C, fallback)``,
    ``fallback`` a boolean mask of the samples where the inversion was non-positive and the
    local power-law factor was used instead.
    """
    q = np.asarray(q, float)
    d = np.asarray(c1d, float)
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
        (default: 10 per decade). Empty bins are dropped.
    window : None or "hann"
        None (default) assumes periodic data and keeps Parseval exact. "hann" multiplies by
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

    Accuracy
    --------
    2-D map: ``psd.h_rms`` equals the rms of the detrended heights to ≲ 0.3 % when the map
    resolves the spectrum (roll-off ≳ 8·q_lo, roughness above q_Ny negligible — energy in the
    FFT corners beyond q_Ny is not represented). Line scans of an isotropic surface: the
    Abel inversion recovers C(q) to a few % in the self-affine band (rows of a 512² map); the
    2-D ``psd.h_rms`` exceeds the profiles' rms by ~1–3 %, because a profile misses the
    roughness whose wavevector is nearly perpendicular to it (|qx| < 2π/L).
    """
    h = _check_heights(heights)
    spacing = _check_spacing(spacing)
    n_bins = _check_n_bins(n_bins)
    _check_choice("window", window, _WINDOWS)
    _check_choice("detrend", detrend, _DETRENDS)
    if not isinstance(line_scans, (bool, np.bool_)):
        raise ValueError(f"line_scans = {line_scans!r} is invalid: must be True or False")
    q_hi = math.pi / spacing
    if h.ndim == 1 or line_scans:
        rows = h[None, :] if h.ndim == 1 else h
        qk, c1, _, _ = _line_periodogram(rows, spacing, window, detrend)
        q_lo = qk[0]
        nb = _default_n_bins(q_lo, q_hi) if n_bins is None else n_bins
        q, d, _ = _log_bin(qk, c1, q_lo, q_hi, nb, dim=1)
        if q.size < 2:
            raise ValueError("heights has (almost) no roughness: fewer than 2 spectrum bins "
                             "are > 0")
        q, d = _extend_to_band(q, d, q_lo, q_hi)
        C, _ = abel_invert(q, d)
        return TabulatedPSD(q, C, convention="persson")

    # ---- 2-D periodic map
    h = _detrend_map(h, detrend)
    ny, nx = h.shape
    if window == "hann":
        h = h * _hann(ny)[:, None] * _hann(nx)[None, :]
    Z = np.fft.fft2(h)
    Ck = (spacing ** 2 / ((2.0 * math.pi) ** 2 * nx * ny)) * (Z.real ** 2 + Z.imag ** 2)
    qy = 2.0 * math.pi * np.fft.fftfreq(ny, spacing)
    qx = 2.0 * math.pi * np.fft.fftfreq(nx, spacing)
    qk = np.hypot(qy[:, None], qx[None, :]).ravel()
    Ck = Ck.ravel()
    q_lo = 2.0 * math.pi / (max(nx, ny) * spacing)
    nb = _default_n_bins(q_lo, q_hi) if n_bins is None else n_bins
    q, C, _ = _log_bin(qk, Ck, q_lo, q_hi, nb, dim=2)
    if q.size < 2:
        raise ValueError("heights has (almost) no roughness: fewer than 2 spectrum bins are > 0")
    q, C = _extend_to_band(q, C, q_lo, q_hi)
    return TabulatedPSD(q, C, convention="persson")


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
    filt = (2.0 * math.pi / spacing) * np.sqrt(psd(qk))
    filt[0, 0] = 0.0
    return np.fft.ifft2(W * filt).real


# ============================================================================ files
def _kind(path):
    name = Path(path).name.lower()
    if name.endswith((".csv", ".csv.gz", ".csv.bz2", ".csv.xz", ".csv.zst")):
        return "csv"
    if name.endswith((".parquet", ".pq")):
        return "parquet"
    raise ValueError(f"path = {str(path)!r} is invalid: must end in .csv (optionally "
                     f"compressed: .csv.gz ...) or .parquet / .pq")


def read_psd(path, convention, *, q_col=None, C_col=None):
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
    if kind == "csv":
        import pandas as pd
        try:
            df = pd.read_csv(path, comment="#", skipinitialspace=True)
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
            raise ValueError(f"path = {path!r} is invalid: cannot read as Parquet ({exc})") from None
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
            raise ValueError(f"{nm} (column {col!r} of {path!r}) is invalid: must be numeric") from None
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
    fd, tmp = tempfile.mkstemp(prefix="." + os.path.basename(path) + ".", suffix=".tmp",
                               dir=folder)
    try:
        if kind == "csv":
            import pandas as pd
            os.close(fd)
            fd = None
            compression = "infer"
            if path.lower().endswith(".csv"):
                compression = None
            else:
                compression = {"method": path.lower().rsplit(".", 1)[-1].replace("bz2", "bz2")
                               .replace("gz", "gzip").replace("zst", "zstd")}
            pd.DataFrame({"q": q, "C": C}).to_csv(tmp, index=False, float_format="%.17g",
                                                  compression=compression)
        else:
            import pyarrow as pa
            import pyarrow.parquet as pq
            os.close(fd)
            fd = None
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
        if fd is not None:
            os.close(fd)
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise
    return path
