"""Boundary-element reference: random surfaces, elastic contact, Reynolds flow on the gap.

:func:`bem_reference` is an *independent* check of Persson's contact theory and of the
Lorenz–Persson flow theories (B. Lorenz & B.N.J. Persson, Eur. Phys. J. E 32, 281 (2010),
arXiv:1004.1037). For each random-phase realization of a power spectrum it

1. synthesizes a periodic n×n height map whose periodogram equals C(q) at every lattice point
   (Persson convention, h_rms² = 2π ∫ q C(q) dq; random phases nested across grids, so n and
   2n grids of one seed carry the same surface — :func:`surface_realization`);
2. solves frictionless, non-adhesive contact of that rigid rough surface with an elastic flat
   half-space of contact modulus E* at each nominal pressure p0 by the constrained conjugate
   gradient method of Polonsky & Keer (Wear 231, 206 (1999), doi:10.1016/S0043-1648(99)00113-1)
   on the periodic half-space Green's function (surface stiffness E*|q|/2; Stanley & Kato,
   J. Tribol. 119, 481 (1997), doi:10.1115/1.2833523), as implemented in ContactMechanics
   (MIT; github.com/ComputationalMechanics/ContactMechanics);
3. solves the Reynolds equation on the resulting gap field
   (:func:`fastcontact.validation.reynolds.reynolds_conductivity`, both directions);
4. locates the pressure at which the flow stops (the contact area percolates) by bisection in
   ln p0 between the last flowing and the first blocked pressure.

It needs the optional extra ``pip install "fastcontact[bem]"`` (ContactMechanics,
SurfaceTopography, tqdm). It runs minutes, not milliseconds: a validation and calibration
tool, never on the hot path.
"""
from __future__ import annotations

import math
import time
import warnings

import numpy as np

__all__ = ["bem_reference", "solve_contact", "surface_realization", "BEMResolutionWarning",
           "UNITS", "MIN_PIXELS_PER_WAVELENGTH", "MIN_ROLLOFF_MODES", "require_extra"]

EXTRA_MESSAGE = 'the BEM reference needs the optional extra: pip install "fastcontact[bem]"'

#: fewer pixels than this per shortest wavelength 2π/q1 under-resolves the contact spots
MIN_PIXELS_PER_WAVELENGTH = 4.0
#: fewer lattice modes than this below the roll-off (q_r·L/2π) makes the box too small for
#: self-averaging (large realization scatter)
MIN_ROLLOFF_MODES = 2.0

UNITS = {
    "p0": "Pa", "area_fraction": "1", "u_mean": "m", "sigma_eff": "m^3/(Pa s)",
    "sigma_xx": "m^3/(Pa s)", "sigma_yy": "m^3/(Pa s)", "n_flowing": "1", "n_seeds": "1",
    "flow_stop_pressure": "Pa", "flow_stop_pressure_std": "Pa", "eta": "Pa s", "E_star": "Pa",
    "box": "m", "pixel": "m", "h_rms_realized": "m",
}


class BEMResolutionWarning(UserWarning):
    """The grid under-resolves the power spectrum (pixels per wavelength, box vs roll-off)."""


def require_extra():
    """Import and return (ContactMechanics, SurfaceTopography) or raise a one-line ImportError."""
    try:
        import ContactMechanics
        import SurfaceTopography
    except ImportError:
        raise ImportError(EXTRA_MESSAGE) from None
    return ContactMechanics, SurfaceTopography


def _versions():
    import importlib.metadata as md

    from .. import __version__

    out = {"fastcontact": __version__}
    for name in ("ContactMechanics", "SurfaceTopography", "numpy", "scipy"):
        try:
            out[name] = md.version(name)
        except md.PackageNotFoundError:
            out[name] = None
    return out


def _check_int(name, value, lo):
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < lo:
        raise ValueError(f"{name} = {value!r} is invalid: must be an integer >= {lo}")
    return int(value)


def _check_pos(name, value, unit):
    v = float(value)
    if not (v > 0.0 and math.isfinite(v)):
        raise ValueError(f"{name} = {value!r} is invalid: must be finite and > 0 {unit}")
    return v


def _nested_uniform(n, seed):
    """Uniform [0,1) numbers per lattice mode that do not depend on n for the modes n and 2n
    share: the mode (i, j) (signed indices) takes its number from the smallest grid m of the
    chain n, n/2, n/4, … (down to an odd size or 8) with max(|i|, |j|) <= (m-1)//2, each grid
    with its own generator ``default_rng([seed, m])``; the modes no sub-grid holds (the
    grid's own Nyquist row and column i = -n/2 or j = -n/2 among them) from the n grid.

    A sub-grid's Nyquist mode (-m/2) is not shared: on the m grid it is its own conjugate
    (phase 0), on the finer grids -m/2 and +m/2 are distinct modes."""
    sizes = [n]
    while sizes[-1] % 2 == 0 and sizes[-1] // 2 >= 8:
        sizes.append(sizes[-1] // 2)
    i = np.fft.fftfreq(n, 1.0 / n).astype(np.int64)
    I, J = np.meshgrid(i, i, indexing="ij")
    reach = np.maximum(np.abs(I), np.abs(J))
    out = np.empty((n, n))
    done = np.zeros((n, n), dtype=bool)
    for m in reversed(sizes):  # smallest first; the n grid takes every mode left
        inside = ~done & ((reach <= (m - 1) // 2) | (m == n))
        r = np.random.default_rng([int(seed), int(m)]).random((m, m))
        out[inside] = r[I[inside] % m, J[inside] % m]
        done |= inside
    return out


def surface_realization(psd, n, box, seed):
    """One random-phase periodic realization h(x) [m] of ``psd`` on an n×n grid of side ``box``.

    ``Z_k = (2π/a) √C(|q_k|) · n e^{iφ_k}``, ``h = Re ifft2(Z)`` (the normalisation of
    :func:`fastcontact.synthetic_heights` with ``random_amplitudes=False``): the periodogram
    equals C(|q|) at every lattice point q = 2π(i, j)/box (Persson convention), so
    ``mean(h²) = Σ_{q≠0} C(q) (2π/box)²`` (Parseval), which tends to ``psd.h_rms²`` when the
    lattice resolves the spectrum. The phases φ_k = 2π[(r_k - r_{-k}) mod 1] are uniform and
    antisymmetric (a real map), with r_k from :func:`_nested_uniform`: the realizations of one
    seed on n and 2n grids share every mode of the coarser grid, so a grid-convergence study
    compares the *same* surface, the finer one adding only shorter wavelengths.
    """
    n = _check_int("n", n, 8)
    box = _check_pos("box", box, "[m]")
    seed = _check_int("seed", seed, 0)
    a = box / n
    r = _nested_uniform(n, seed)
    idx = (-np.arange(n)) % n
    phi = 2.0 * math.pi * np.mod(r - r[idx][:, idx], 1.0)
    q1d = 2.0 * math.pi * np.fft.fftfreq(n, a)
    qk = np.hypot(q1d[:, None], q1d[None, :])
    for edge in (psd.q0, psd.q1):  # a lattice point equal to q0 or q1 up to round-off
        qk[np.abs(qk / edge - 1.0) < 1e-9] = edge
    filt = (2.0 * math.pi / a) * np.sqrt(np.asarray(psd(qk), dtype=np.float64))
    filt[0, 0] = 0.0
    return np.fft.ifft2(n * np.exp(1j * phi) * filt).real


def resolution_report(psd, n, box):
    """Pixels per shortest wavelength, lattice modes below the roll-off and warnings (strings)."""
    a = box / n
    ppw = (2.0 * math.pi / psd.q1) / a
    q_lat = 2.0 * math.pi / box
    q_roll = getattr(psd, "q_roll", None) or psd.q0
    modes = q_roll / q_lat
    msgs = []
    if ppw < MIN_PIXELS_PER_WAVELENGTH:
        msgs.append(f"grid under-resolves the PSD: {ppw:.3g} pixels per shortest wavelength "
                    f"2π/q1 (want >= {MIN_PIXELS_PER_WAVELENGTH:g}); the roughness above "
                    f"q = {2 * math.pi / (MIN_PIXELS_PER_WAVELENGTH * a):.4g} 1/m is poorly "
                    f"resolved — raise n or lower q1")
    if psd.q1 > math.pi / a:
        msgs.append(f"q1 = {psd.q1:.4g} 1/m lies beyond the grid's Nyquist wavevector "
                    f"π/a = {math.pi / a:.4g} 1/m: the finest roughness is missing")
    if q_lat > psd.q0 * (1.0 + 1e-9):
        msgs.append(f"box = {box:.4g} m is smaller than 2π/q0 = {2 * math.pi / psd.q0:.4g} m: "
                    f"the longest wavelengths of the PSD are missing")
    if modes < MIN_ROLLOFF_MODES:
        msgs.append(f"box holds only {modes:.3g} lattice modes below the roll-off "
                    f"(q_roll·box/2π, want >= {MIN_ROLLOFF_MODES:g}): realizations will scatter "
                    f"strongly; use a larger box than 2π/q_roll or more seeds")
    return {"pixels_per_wavelength": ppw, "rolloff_modes": modes, "warnings": msgs}


def solve_contact(heights, box, E_star, p0, *, periodic=True, initial=None, pentol=None,
                  maxiter=20000):
    """Frictionless contact of a rigid surface ``heights`` with an elastic flat [Polonsky–Keer].

    Parameters
    ----------
    heights : (n, n) ndarray
        Rigid surface heights [m] (larger = higher, towards the elastic body).
    box : float
        Side length of the (square) domain [m].
    E_star : float
        Contact modulus E* [Pa] of the elastic body.
    p0 : float
        Nominal pressure [Pa] (total force / box²), > 0.
    periodic : bool
        Periodic half-space (default) or a free (non-periodic, zero-padded) half-space — the
        latter for isolated contacts such as Hertz.
    initial : ndarray, optional
        Initial displacement field (scaled units of a previous call's ``"state"``).
    pentol : float, optional
        Penetration tolerance [m]; default 1e-4 · rms height (or 1e-6 · peak-to-valley).

    Returns
    -------
    dict
        ``gap`` [m] (0 in contact), ``pressure`` [Pa] per pixel, ``area_fraction`` [-],
        ``u_mean`` [m] (mean gap over the box), ``iterations``, ``state`` (warm start).
    """
    require_extra()
    from ContactMechanics import FreeFFTElasticHalfSpace, PeriodicFFTElasticHalfSpace
    from ContactMechanics.Optimization import constrained_conjugate_gradients
    from SurfaceTopography import Topography

    h = np.asarray(heights, dtype=np.float64)
    if h.ndim != 2 or h.shape[0] != h.shape[1]:
        raise ValueError(f"heights with shape {h.shape} is invalid: must be a square n×n array [m]")
    n = h.shape[0]
    box = _check_pos("box", box, "[m]")
    E_star = _check_pos("E_star", E_star, "[Pa]")
    p0 = _check_pos("p0", p0, "[Pa]")
    a = box / n
    # scaled problem: lengths in pixels, stresses in E* (CCG tolerances are absolute)
    hs = h / a
    pbar = p0 / E_star
    Half = PeriodicFFTElasticHalfSpace if periodic else FreeFFTElasticHalfSpace
    sub = Half((n, n), 1.0, physical_sizes=(float(n), float(n)))
    top = Topography(hs, physical_sizes=(float(n), float(n)), periodic=bool(periodic))
    if pentol is None:
        rms = float(np.std(hs))
        pentol = 1e-4 * rms if rms > 0 else 1e-6 * float(np.ptp(hs))
    else:
        pentol = _check_pos("pentol", pentol, "[m]") / a
    res = constrained_conjugate_gradients(
        sub, top, external_force=pbar * n * n, initial_displacements=initial, pentol=pentol,
        forcetol=1e-8 * pbar, maxiter=int(maxiter))
    if not res.success:
        raise RuntimeError(f"contact solver did not converge at p0 = {p0:.6g} Pa "
                           f"({res.nit} iterations, {res.message})")
    force = np.asarray(res.jac)[:n, :n]
    u = np.asarray(res.x)[:n, :n]
    contact = force > 0.0
    gap = np.where(contact, 0.0, np.maximum(u - hs - res.offset, 0.0)) * a
    return {"gap": gap, "pressure": force * E_star, "area_fraction": float(contact.mean()),
            "u_mean": float(gap.mean()), "iterations": int(res.nit), "state": np.asarray(res.x)}


def _one_pressure(h, box, E_star, p, eta, init):
    from .reynolds import reynolds_conductivity

    c = solve_contact(h, box, E_star, p, initial=init)
    s = reynolds_conductivity(c["gap"], eta)
    return c, s


def _flow_stop(h, box, E_star, p_lo, p_hi, state_lo, eta, steps):
    """Bisection in ln p for the pressure at which σ_xx = σ_yy = 0 (flow stops)."""
    from .reynolds import reynolds_conductivity

    for _ in range(steps):
        pm = math.sqrt(p_lo * p_hi)
        c = solve_contact(h, box, E_star, pm, initial=state_lo)
        s = reynolds_conductivity(c["gap"], eta)
        if s["x"] > 0.0 or s["y"] > 0.0:
            p_lo, state_lo = pm, c["state"]
        else:
            p_hi = pm
    return math.sqrt(p_lo * p_hi), 0.5 * math.log(p_hi / p_lo)


def _describe(psd):
    try:
        return psd.to_dict()
    except Exception:  # pragma: no cover - every fastcontact PSD has to_dict
        return {"repr": repr(psd)}


def _reference_inputs(psd, E_star, p0, n, seeds, eta, box, stop_bisections):
    """The checked inputs of :func:`bem_reference`: (p [Pa] sorted, E* [Pa], η [Pa·s], n,
    seeds, box [m], stop_bisections); ImportError without the extra, ValueError if bad."""
    require_extra()
    if not hasattr(psd, "q1") or not hasattr(psd, "h_rms"):
        raise ValueError(f"psd = {psd!r} is invalid: must be a fastcontact PSD object")
    E_star = _check_pos("E_star", E_star, "[Pa]")
    eta = _check_pos("eta", eta, "[Pa·s]")
    n = _check_int("n", n, 16)
    p = np.sort(np.atleast_1d(np.asarray(p0, dtype=np.float64)).ravel())
    if p.size == 0 or not np.all(np.isfinite(p)) or np.any(p <= 0):
        raise ValueError(f"p0 = {p0!r} is invalid: must be finite pressures > 0 [Pa]")
    seeds = list(np.atleast_1d(seeds))
    if not seeds:
        raise ValueError("seeds = [] is invalid: must hold at least one seed")
    box = 2.0 * math.pi / psd.q0 if box is None else _check_pos("box", box, "[m]")
    stop_bisections = _check_int("stop_bisections", stop_bisections, 0)
    return p, E_star, eta, n, seeds, box, stop_bisections


def _progress_bar(total, progress):
    """A tqdm bar of ``total`` solves, or None (``progress`` off, or no tqdm)."""
    if not progress:
        return None
    try:
        from tqdm.auto import tqdm
        return tqdm(total=total, desc="BEM reference", unit="solve")
    except ImportError:
        return None


def _pressure_scan(h, box, E_star, p, eta, find_stop, stop_bisections, bar):
    """Contact and flow of one realization ``h`` [m] at each pressure of ``p`` [Pa] (ascending,
    each solve warm-started from the previous one).

    Returns
    -------
    rows : (len(p), 4) ndarray
        A/A0 [-], ū [m], σ_xx and σ_yy [m³/(Pa·s)] per pressure.
    stop : (float, float)
        With ``find_stop``, the flow-stop pressure [Pa] bisected between the last flowing and
        the first blocked pressure and its half log bracket; else (or if the flow never
        stops) (NaN, NaN).
    iterations : int
        Conjugate-gradient iterations of the pressures in ``p`` (not of the bisection).
    """
    rows, state, prev, stop, iters = [], None, None, (math.nan, math.nan), 0
    for k, pk in enumerate(p):
        c, s = _one_pressure(h, box, E_star, float(pk), eta, state)
        iters += c["iterations"]
        flowing = s["x"] > 0.0 or s["y"] > 0.0
        if find_stop and math.isnan(stop[0]) and not flowing and prev is not None and prev[1]:
            stop = _flow_stop(h, box, E_star, float(p[k - 1]), float(pk), prev[0], eta,
                              stop_bisections)
        prev = (c["state"], flowing)
        state = c["state"]
        rows.append((c["area_fraction"], c["u_mean"], s["x"], s["y"]))
        if bar is not None:
            bar.update(1)
    return np.array(rows), stop, iters


def _solve_realizations(psd, box, E_star, p, eta, n, jobs, stop_bisections, progress):
    """Each (grid size, seed) of ``jobs`` solved at every pressure of ``p`` [Pa], with the
    flow-stop pressure of the n-grid realizations.

    Returns
    -------
    results : dict
        {(grid size, seed): the rows of :func:`_pressure_scan`}.
    stops : dict
        {seed: (flow-stop pressure [Pa], half log bracket)} of the n-grid realizations.
    run : dict
        ``h_rms_realized`` [m] (rms height of each n-grid realization), ``cg_iterations``
        and ``seconds`` (wall time of the solves).
    """
    bar = _progress_bar(len(jobs) * p.size, progress)
    t_start = time.perf_counter()
    results = {}
    stops = {}
    h_real = []
    iters = 0
    for nn, seed in jobs:
        h = surface_realization(psd, nn, box, int(seed))
        if nn == n:
            h_real.append(float(np.sqrt(np.mean(h ** 2))))
        results[(nn, seed)], stop, it = _pressure_scan(h, box, E_star, p, eta, nn == n,
                                                       stop_bisections, bar)
        iters += it
        if nn == n:
            stops[int(seed)] = stop
    if bar is not None:
        bar.close()
    return results, stops, {"h_rms_realized": h_real, "cg_iterations": iters,
                            "seconds": time.perf_counter() - t_start}


def _seed_columns(p, R):
    """The seed means and standard deviations of the (seeds × pressures × 4) results ``R``
    (columns of :func:`_pressure_scan`), as the columns of the reference table."""
    sig = 0.5 * (R[:, :, 2] + R[:, :, 3])
    ddof = 1 if R.shape[0] > 1 else 0
    return {
        "p0": p,
        "area_fraction": R[:, :, 0].mean(0), "area_fraction_std": R[:, :, 0].std(0, ddof=ddof),
        "u_mean": R[:, :, 1].mean(0), "u_mean_std": R[:, :, 1].std(0, ddof=ddof),
        "sigma_eff": sig.mean(0), "sigma_eff_std": sig.std(0, ddof=ddof),
        "sigma_xx": R[:, :, 2].mean(0), "sigma_yy": R[:, :, 3].mean(0),
        "n_flowing": (sig > 0).sum(0).astype(np.int64),
    }


def _add_grid_errors(df, units, fine, coarse):
    """Add the ``*_grid_err`` columns to ``df`` (and their units): the relative difference of
    the n/2 grid's results ``coarse`` from the n grid's ``fine`` (one seed)."""
    for j, col in ((0, "area_fraction"), (1, "u_mean")):
        df[f"{col}_grid_err"] = np.abs(fine[:, j] - coarse[:, j]) / np.abs(fine[:, j])
    sf = 0.5 * (fine[:, 2] + fine[:, 3])
    sc = 0.5 * (coarse[:, 2] + coarse[:, 3])
    with np.errstate(divide="ignore", invalid="ignore"):
        df["sigma_eff_grid_err"] = np.where(sf > 0, np.abs(sf - sc) / sf, np.nan)
    for col in ("area_fraction", "u_mean", "sigma_eff"):
        units[f"{col}_grid_err"] = "1"


def _per_seed(rows):
    """One seed's A/A0 [-], ū [m] and σ_eff [m³/(Pa·s)] per pressure, as lists."""
    return {"area_fraction": rows[:, 0].tolist(), "u_mean": rows[:, 1].tolist(),
            "sigma_eff": (0.5 * (rows[:, 2] + rows[:, 3])).tolist()}


def _provenance(psd, n, seeds, box, res_info, grid_check, stop_bisections, run):
    """``attrs["provenance"]`` of a reference: method, grid, seeds, box and pixel [m], PSD,
    resolution, the solves' record ``run`` (:func:`_solve_realizations`) and versions."""
    return {
        "method": "ContactMechanics constrained conjugate gradients (Polonsky-Keer), "
                  "periodic half-space; Reynolds finite volumes, harmonic face "
                  "conductance, imposed mean gradient along x and y",
        "n": n, "seeds": [int(s) for s in seeds], "box": box, "pixel": box / n,
        "psd": _describe(psd), "psd_h_rms": float(psd.h_rms),
        "h_rms_realized": run["h_rms_realized"],
        "pixels_per_wavelength": res_info["pixels_per_wavelength"],
        "rolloff_modes": res_info["rolloff_modes"],
        "grid_check_n": n // 2 if grid_check else None,
        "stop_bisections": stop_bisections,
        "cg_iterations": run["cg_iterations"], "seconds": run["seconds"],
        "versions": _versions(),
    }


def bem_reference(psd, E_star, p0, *, n=256, seeds=(0, 1, 2), eta=1e-3, box=None,
                  stop_bisections=4, grid_check=True, progress=True):
    """BEM + Reynolds reference for A/A0, ū and σ_eff versus nominal pressure.

    Parameters
    ----------
    psd : fastcontact PSD
        Roughness spectrum C(q) [m⁴] (Persson convention, h_rms² = 2π∫qC dq).
    E_star : float
        Contact modulus E* [Pa] (elastic block on a rigid rough substrate).
    p0 : array_like
        Nominal (contact) pressures [Pa], > 0; sorted ascending internally.
    n : int
        Grid points per side (≥ 16; powers of two are fastest).
    seeds : sequence of int
        Random seeds, one realization each (≥ 1).
    eta : float
        Fluid viscosity η [Pa·s] for ``sigma_eff`` (σ ∝ 1/η).
    box : float, optional
        Side of the periodic box [m]; default 2π/q0 (lowest lattice wavevector = q0).
    stop_bisections : int
        Bisection steps in ln p0 for the flow-stop pressure (each halves its log bracket).
    grid_check : bool
        Also solve the first seed on an n/2 grid (same box) and report the relative
        coarse-vs-fine difference of each quantity (``*_grid_err`` columns) — the residual grid
        error of the n-grid result is at most that for a first-order convergent quantity.
    progress : bool
        Show a tqdm progress bar.

    Returns
    -------
    pandas.DataFrame
        One row per pressure: ``p0`` [Pa], ``area_fraction`` [-], ``u_mean`` [m],
        ``sigma_eff`` [m³/(Pa·s)] (mean of σ_xx and σ_yy, averaged over seeds),
        ``sigma_xx``, ``sigma_yy``, each with ``*_std`` (seed standard deviation),
        ``n_flowing`` (seeds with σ > 0) and, with ``grid_check``, ``*_grid_err``.
        ``attrs`` hold ``units``, ``eta``, ``E_star``, ``flow_stop_pressure`` [Pa] (mean over
        seeds; NaN if flow never stops in the range), ``flow_stop_pressure_std``,
        ``flow_stop_per_seed``, ``per_seed`` (each seed's columns), ``provenance`` (grid,
        seeds, box, pixel, psd, versions, resolution, timing) and ``warnings``.
    """
    import pandas as pd

    p, E_star, eta, n, seeds, box, stop_bisections = _reference_inputs(
        psd, E_star, p0, n, seeds, eta, box, stop_bisections)
    res_info = resolution_report(psd, n, box)
    for msg in res_info["warnings"]:
        warnings.warn(msg, BEMResolutionWarning, stacklevel=2)

    jobs = [(n, s) for s in seeds] + ([(n // 2, seeds[0])] if grid_check else [])
    results, stops, run = _solve_realizations(psd, box, E_star, p, eta, n, jobs,
                                              stop_bisections, progress)

    df = pd.DataFrame(_seed_columns(p, np.stack([results[(n, s)] for s in seeds])))
    units = dict(UNITS, **{f"{col}_std": UNITS[col]
                           for col in ("area_fraction", "u_mean", "sigma_eff")})
    if grid_check:
        _add_grid_errors(df, units, results[(n, seeds[0])], results[(n // 2, seeds[0])])
    sv = np.array([stops[int(s)][0] for s in seeds])
    ok = np.isfinite(sv)
    warn = list(res_info["warnings"])
    if not ok.all():
        warn.append(f"flow did not stop below p0 = {p[-1]:.4g} Pa in {int((~ok).sum())} of "
                    f"{len(seeds)} realizations: raise the largest pressure to bracket it")
        if ok.any():
            warnings.warn(warn[-1], UserWarning, stacklevel=2)
    df.attrs = {
        "units": units, "eta": eta, "E_star": E_star,
        "flow_stop_pressure": float(np.exp(np.mean(np.log(sv[ok])))) if ok.any() else math.nan,
        "flow_stop_pressure_std": float(np.std(sv[ok], ddof=1)) if ok.sum() > 1 else math.nan,
        "flow_stop_per_seed": {str(s): stops[int(s)][0] for s in seeds},
        "per_seed": {str(s): _per_seed(results[(n, s)]) for s in seeds},
        "flow_stop_log_bracket": max((stops[int(s)][1] for s in seeds if
                                      np.isfinite(stops[int(s)][1])), default=math.nan),
        "provenance": _provenance(psd, n, seeds, box, res_info, grid_check, stop_bisections,
                                  run),
        "warnings": warn,
    }
    return df
