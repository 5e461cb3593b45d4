"""Reduced (asymptotic) squeeze-out model of Sec. 2 of the paper, the flat-surface Stefan
law and the inertia-limited estimate of Sec. 5 (Lorenz & Persson 2010, arXiv:1004.1037).

The block (flat, radius R) is pressed with the nominal pressure p0 against a rigid
randomly rough substrate in a Newtonian fluid. For large separations the asperity contact
pressure follows the asymptotic law (3), and the average-separation flow model (1) gives
a single autonomous ODE for ū(t) (eq. 10). Since the right-hand side depends on ū only,
the time to go from ū_a down to ū_b is the quadrature

    t(ū_a → ū_b) = ∫_{ū_b}^{ū_a} dū / |dū/dt| = ∫_{ū_b}^{ū_a} α dū / (ū³ (1 - κ⁻¹e^{-αū}))

(reduced units), which is what this module evaluates — no time stepping.

Reduced units (paper Sec. 2)
----------------------------
separation in h_rms, pressure in p0, time in τ = 3ηR²/(2α h_rms² p0) (eq. 6). Functions
whose name ends in ``_reduced`` take and return reduced quantities; all others are SI.

Glossary
--------
h_rms    rms roughness amplitude of the substrate [m]
u0       decay length of the asymptotic law (3), u0 = h_rms/α [m]
α        h_rms/u0 of law (3) [-] (paper's illustrative value 0.5). NOT the critical-junction
         factor of Sec. 3, which the paper also calls α.
β        prefactor of law (3), p_cont ≈ β E* exp(-ū/u0) [-] (paper's illustrative value 1)
E_star   effective modulus E* = E/(1-ν²) [Pa]
p0       nominal (applied) squeezing pressure [Pa]
η, eta   fluid viscosity [Pa·s]
R        radius of the cylindrical block [m]; D = 2R its diameter [m]
ρ, rho   fluid mass density [kg/m³]
τ, tau   viscous time unit, eq. (6) [s]
τ'       inertial time constant (Sec. 5) [s]
κ        p0/(βE*), eq. (9) [-]; the only pressure parameter of the reduced model
ū        average interfacial separation [m], or [h_rms] in reduced units
p_cont   asperity contact pressure [Pa], or [p0] in reduced units; p_cont = κ⁻¹e^{-αū} (8)
ū∞       equilibrium separation, p_cont(ū∞) = p0: ū∞ = ln(1/κ)/α [h_rms]; exists for κ < 1
t*       squeeze-out time, ū(t*) = ratio·ū∞ (paper: ratio = 1.01) [τ]
u_start  initial separation ū(0) [h_rms]

Numerics of t*
--------------
With v = ū - ū∞ the factor 1 - p_cont = -expm1(-αv) exactly (no cancellation), and with
w = ln v (dū = v dw) the integrand α v / (ū³ (-expm1(-αv))) is bounded and analytic in a strip
|Im w| < π/2: the logarithmic divergence of t as ū → ū∞ becomes a long but flat integration
range. It is integrated with composite 20-point Gauss–Legendre panels (width 1 near the
features at v ~ ū∞, v ~ 2π/α; geometrically widening below them, where the integrand tends
to the constant 1/ū∞³). Above v = 40/α the factor 1 - e^{-αv} equals 1 to within 4e-18 and
the rest of the integral is done in closed form (so u_start = +inf is allowed). Measured
agreement with a 30-digit mpmath quadrature of the integral in ū: ≤ 1e-14 relative (see
tests/test_reduced.py). ū(t) is obtained by a safeguarded Newton iteration on t(ū) in w.
The numba kernels of both live in :mod:`fastcontact.squeeze._reduced_kernels`.

For κ ≥ 1 law (8) gives p_cont < p0 at every ū > 0: the asymptotic model has no positive
equilibrium, ū(t) → 0 like the flat-surface law, and t* is infinite. Such cases are flagged
(``valid = False``), never returned as a silent number.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from .._core.validate import check_positive, check_range
from ._reduced_kernels import _GLW, _GLX, _t_star_kernel, _u_of_t_kernel

__all__ = [
    "time_unit_tau",
    "kappa_parameter",
    "contact_pressure_reduced",
    "separation_rate_reduced",
    "equilibrium_separation_reduced",
    "default_u_start_reduced",
    "squeeze_out_reduced",
    "u_of_t_reduced",
    "flat_separation",
    "flat_separation_reduced",
    "inertia_time_constant",
    "inertia_squeeze_time",
    "inertia_separation",
    "DEFAULT_P_START",
    "ASYMPTOTIC_MIN_SEPARATION",
]

#: Default initial condition: ū(0) is where the asperity contact pressure is this fraction
#: of p0, p_cont(ū(0)) = 1e-3 p0, i.e. ū(0) = ū∞ + ln(1000)/α (see default_u_start_reduced).
DEFAULT_P_START = 1e-3

#: The paper (Sec. 5) uses the theory of Sec. 2 where ū > 2 h_rms; below that law (3) is
#: not trusted. Rows of squeeze_out_reduced with ū∞ < 2 get ``large_separation = False``.
ASYMPTOTIC_MIN_SEPARATION = 2.0

# =========================================================================== SI helpers
def time_unit_tau(eta, R, h_rms, p0, alpha):
    """Viscous time unit τ = 3ηR² / (2α h_rms² p0) [s] — paper eq. (6).

    Parameters
    ----------
    eta : array_like
        Viscosity η [Pa·s].
    R : array_like
        Block radius [m].
    h_rms : array_like
        Rms roughness [m].
    p0 : array_like
        Nominal squeezing pressure [Pa].
    alpha : array_like
        h_rms/u0 of law (3) [-].
    """
    eta = check_positive("eta", eta, "[Pa·s]")
    R = check_positive("R", R, "[m]")
    h_rms = check_positive("h_rms", h_rms, "[m]")
    p0 = check_positive("p0", p0, "[Pa]")
    alpha = check_positive("alpha", alpha, "[-]")
    return _scalar_or_array(3.0 * eta * R**2 / (2.0 * alpha * h_rms**2 * p0))


def kappa_parameter(p0, E_star, beta=1.0):
    """κ = p0 / (β E*) [-] — paper eq. (9).

    Parameters
    ----------
    p0 : array_like
        Nominal squeezing pressure [Pa].
    E_star : array_like
        Effective modulus E* [Pa].
    beta : array_like
        Prefactor β of the asymptotic law (3) [-] (paper's illustration: 1).
    """
    p0 = check_positive("p0", p0, "[Pa]")
    E_star = check_positive("E_star", E_star, "[Pa]")
    beta = check_positive("beta", beta, "[-]")
    return _scalar_or_array(p0 / (beta * E_star))


# =========================================================================== reduced model
def _checked_state(u, kappa, alpha):
    """(u, kappa, alpha) as validated arrays: ū [h_rms] >= 0, κ [-] > 0, α [-] > 0."""
    return (check_positive("u", u, "[h_rms]", allow_zero=True),
            check_positive("kappa", kappa, "[-]"),
            check_positive("alpha", alpha, "[-]"))


def contact_pressure_reduced(u, kappa, alpha):
    """Asperity contact pressure p_cont = κ⁻¹ e^{-αū} [p0] — paper eq. (8) (law (3) reduced).

    Parameters
    ----------
    u : array_like
        Separation ū [h_rms], ≥ 0.
    kappa : array_like
        p0/(βE*) [-], > 0.
    alpha : array_like
        h_rms/u0 [-], > 0.
    """
    u, kappa, alpha = _checked_state(u, kappa, alpha)
    return _scalar_or_array(np.exp(-alpha * u - np.log(kappa)))


def separation_rate_reduced(u, kappa, alpha):
    """dū/dt = -α⁻¹ ū³ (1 - p_cont(ū)) [h_rms/τ] — paper eq. (10) with law (8).

    Equivalent to eq. (7), dp_cont/dt = ū³ p_cont (1 - p_cont). Written with
    1 - κ⁻¹e^{-αū} = -expm1(-αū - ln κ) so that it is accurate next to equilibrium.

    Parameters
    ----------
    u, kappa, alpha : array_like
        As in :func:`contact_pressure_reduced`: ū [h_rms] ≥ 0, κ = p0/(βE*) [-] > 0,
        α = h_rms/u0 [-] > 0.
    """
    u, kappa, alpha = _checked_state(u, kappa, alpha)
    return _scalar_or_array(u**3 * np.expm1(-alpha * u - np.log(kappa)) / alpha)


def equilibrium_separation_reduced(kappa, alpha):
    """Equilibrium separation ū∞ = ln(1/κ)/α [h_rms], where p_cont(ū∞) = p0 — paper Sec. 2
    (below eq. 6: u∞ = u0 ln(βE*/p0)).

    Only κ < 1 has a positive equilibrium; a ValueError is raised otherwise (use
    :func:`squeeze_out_reduced`, which flags κ ≥ 1 rows instead).

    Parameters
    ----------
    kappa : array_like
        p0/(βE*) [-], in (0, 1).
    alpha : array_like
        h_rms/u0 [-], > 0.
    """
    kappa = check_range("kappa", kappa, 0.0, 1.0,
                        "[-] (p0/(beta E*); kappa >= 1 has no positive equilibrium)",
                        lo_open=True, hi_open=True)
    alpha = check_positive("alpha", alpha, "[-]")
    return _scalar_or_array(-np.log(kappa) / alpha)


def default_u_start_reduced(kappa, alpha, p_start=DEFAULT_P_START):
    """Default initial separation ū(0) [h_rms]: p_cont(ū(0)) = p_start·p0, i.e.
    ū(0) = ū∞ + ln(1/p_start)/α (= ū∞ + ln(1000)/α for the default p_start = 1e-3).

    Why: the paper integrates its eq. (7), whose state variable is p_cont in units of p0, so
    a κ-independent initial contact pressure p_cont(0) ≪ p0 is the natural initial
    condition; and the caption of its Fig. 2 draws a separate flat-surface curve for every
    κ, which in reduced units only happens if ū(0) depends on κ (the flat law in reduced
    units has no κ). 1e-3 puts ū(0) ln(1000)/α ≈ 6.9/α h_rms above equilibrium: the fluid
    carries 99.9 % of the load at t = 0.

    For κ ≥ 1 (no equilibrium) ū∞ is replaced by 0, giving ū(0) = ln(1/p_start)/α.
    """
    kappa = check_positive("kappa", kappa, "[-]")
    alpha = check_positive("alpha", alpha, "[-]")
    p_start = check_range("p_start", p_start, 0.0, 1.0, "[p0]", lo_open=True, hi_open=True)
    u_inf = np.maximum(-np.log(kappa), 0.0) / alpha
    return _scalar_or_array(u_inf - np.log(p_start) / alpha)


def squeeze_out_reduced(kappa, alpha, u_start=None, ratio=1.01):
    """Squeeze-out time t* and final separation of the asymptotic model — paper eqs. (7)–(10),
    Figs. 2–3.

    t* is the time (units τ, eq. 6) for ū to fall from ``u_start`` to ``ratio``·ū∞,

        t* = ∫_{ratio·ū∞}^{u_start} α dū / (ū³ (1 - κ⁻¹e^{-αū})),

    evaluated by quadrature (see the module docstring; accuracy ~1e-14 relative).

    Parameters
    ----------
    kappa : array_like, p0/(βE*) [-], > 0 (eq. 9).
    alpha : array_like, h_rms/u0 [-], > 0.
    u_start : array_like or None, initial separation ū(0) [h_rms], > ratio·ū∞ (may be +inf:
        the integral converges, ū(t) then starts on the Stefan attractor (α/2t)^{1/2}).
        None (default): ū(0) = ū∞ + ln(1000)/α, where p_cont(0) = 1e-3 p0
        (:func:`default_u_start_reduced`).
    ratio : array_like, the target ū(t*)/ū∞ [-], > 1 (paper: 1.01; also 1.1, 1.001).

    All four broadcast against each other like numpy arrays; the result has one row per
    broadcast element (C order).

    Returns
    -------
    pandas.DataFrame with columns

    ``kappa, alpha, u_start, ratio`` the (broadcast) inputs;
    ``u_inf``   ū∞ = ln(1/κ)/α [h_rms]; 0.0 where κ ≥ 1 (ū(t) → 0, no positive equilibrium);
    ``u_star``  ratio·ū∞ = ū(t*) [h_rms]; 0.0 where κ ≥ 1;
    ``t_star``  t* [τ]; +inf where κ ≥ 1;
    ``p_start`` p_cont(u_start) [p0];
    ``relax_time`` 1/ū∞³ [τ], the e-folding time of the final exponential approach
               ū - ū∞ ∝ exp(-ū∞³ t) (paper, below eq. 6); +inf where κ ≥ 1;
    ``valid``   True iff κ < 1 (a positive equilibrium and a finite t* exist);
    ``large_separation`` True iff ū∞ ≥ 2 (the paper's validity condition for law (3),
               Sec. 5); False rows are computed but law (3) is outside its range there;
    ``status``  "ok", "small_separation" (valid, ū∞ < 2) or "no_equilibrium" (κ ≥ 1).

    Raises
    ------
    ValueError naming the parameter if any input is out of range, in particular if
    u_start ≤ ratio·ū∞ for a case with κ < 1 (the film is already at or below the target;
    starting below ū∞ the asymptotic model would have negative fluid pressure).
    """
    kappa = check_positive("kappa", kappa, "[-]")
    alpha = check_positive("alpha", alpha, "[-]")
    ratio = check_positive("ratio", ratio, "[-]", allow_inf=False)
    if np.any(ratio <= 1.0):
        bad = ratio[ratio <= 1.0].ravel()[0]
        raise ValueError(f"ratio = {float(bad)!r} is invalid: must be a finite number > 1 [-] "
                         f"(target u(t*)/u_inf)")
    if u_start is None:
        u_start = np.asarray(default_u_start_reduced(kappa, alpha), dtype=np.float64)
    else:
        u_start = check_positive("u_start", u_start, "[h_rms]", allow_inf=True)
    kappa, alpha, u_start, ratio = (np.ascontiguousarray(a, dtype=np.float64).ravel()
                                    for a in np.broadcast_arrays(kappa, alpha, u_start, ratio))
    valid = kappa < 1.0
    u_inf = np.where(valid, -np.log(np.where(valid, kappa, 0.5)) / alpha, 0.0)
    u_star = ratio * u_inf
    bad = valid & ~(u_start > u_star)
    if np.any(bad):
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(
            f"u_start = {float(u_start[i])!r} is invalid: must be > ratio*u_inf = "
            f"{float(u_star[i])!r} [h_rms] (kappa = {float(kappa[i])!r}, "
            f"alpha = {float(alpha[i])!r}, ratio = {float(ratio[i])!r})")
    t_star = np.empty_like(kappa)
    _t_star_kernel(kappa, alpha, u_start, ratio, _GLX, _GLW, t_star)
    with np.errstate(divide="ignore", over="ignore"):
        relax = np.where(valid, 1.0 / np.where(valid, u_inf, 1.0) ** 3, np.inf)
        p_start = np.exp(-alpha * u_start - np.log(kappa))
    large = valid & (u_inf >= ASYMPTOTIC_MIN_SEPARATION)
    status = np.where(~valid, "no_equilibrium", np.where(large, "ok", "small_separation"))
    return pd.DataFrame({
        "kappa": kappa, "alpha": alpha, "u_start": u_start, "ratio": ratio,
        "u_inf": u_inf, "u_star": u_star, "t_star": t_star, "p_start": p_start,
        "relax_time": relax, "valid": valid, "large_separation": large, "status": status,
    })


def u_of_t_reduced(kappa, alpha, t, u_start=None):
    """Separation ū(t) [h_rms] of the asymptotic model at reduced times t [τ] — solution of
    paper eq. (10) with law (8), ū(0) = u_start.

    Obtained by inverting the monotone time quadrature t(ū) = ∫_ū^{u_start} α dū'/(ū'³(1 - p))
    with a safeguarded Newton iteration in w = ln(ū - ū∞); relative accuracy ~1e-13.

    Parameters
    ----------
    kappa : array_like, p0/(βE*) [-], > 0.
    alpha : array_like, h_rms/u0 [-], > 0.
    t : array_like, reduced time [τ], ≥ 0 (+inf allowed: returns the limit).
    u_start : array_like or None, ū(0) [h_rms], > ū∞ (+inf allowed); None: the default of
        :func:`default_u_start_reduced` (p_cont(0) = 1e-3 p0).

    All broadcast together; returns an array of the broadcast shape (a float for scalars).
    ū(t) decreases monotonically from u_start towards ū∞ (κ < 1). For κ ≥ 1 there is no
    positive equilibrium and ū(t) → 0 like t^{-1/2} (κ > 1) or t^{-1/3} (κ = 1): the values
    are the exact solution of eq. (10) with law (8), but law (8) is outside its range of
    validity there (see the ``valid`` flag of :func:`squeeze_out_reduced`).
    """
    kappa = check_positive("kappa", kappa, "[-]")
    alpha = check_positive("alpha", alpha, "[-]")
    t = check_positive("t", t, "[tau]", allow_zero=True, allow_inf=True)
    if u_start is None:
        u_start = np.asarray(default_u_start_reduced(kappa, alpha), dtype=np.float64)
    else:
        u_start = check_positive("u_start", u_start, "[h_rms]", allow_inf=True)
    kb, ab, tb, ub = np.broadcast_arrays(kappa, alpha, t, u_start)
    shape = kb.shape
    kb, ab, tb, ub = (np.ascontiguousarray(a, dtype=np.float64).ravel() for a in (kb, ab, tb, ub))
    u_inf = np.where(kb < 1.0, -np.log(np.minimum(kb, 1.0)) / ab, 0.0)
    bad = ~(ub > u_inf)
    if np.any(bad):
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(f"u_start = {float(ub[i])!r} is invalid: must be > u_inf = "
                         f"{float(u_inf[i])!r} [h_rms] (kappa = {float(kb[i])!r}, "
                         f"alpha = {float(ab[i])!r})")
    out = np.empty_like(kb)
    _u_of_t_kernel(kb, ab, ub, tb, _GLX, _GLW, out)
    return _scalar_or_array(out.reshape(shape))


# =========================================================================== flat surfaces
def flat_separation(u0, t, p0, eta, R):
    """Film thickness between flat surfaces (Stefan–Reynolds law, eq. (1) with p_cont = 0) [m]:

        ū(t) = ū0 [1 + 4 ū0² p0 t / (3ηR²)]^{-1/2},

    the solution of paper eq. (1) with p_fluid = p0 (no contact). ū → (3ηR²/(4p0 t))^{1/2}
    ∝ t^{-1/2}: no finite squeeze-out time (paper Sec. 2).

    Parameters
    ----------
    u0 : array_like
        Initial film thickness ū(0) [m], > 0.
    t : array_like
        Time [s], ≥ 0.
    p0 : array_like
        Nominal squeezing pressure [Pa].
    eta : array_like
        Viscosity η [Pa·s].
    R : array_like
        Block radius [m].
    """
    u0 = check_positive("u0", u0, "[m]")
    t = check_positive("t", t, "[s]", allow_zero=True)
    p0 = check_positive("p0", p0, "[Pa]")
    eta = check_positive("eta", eta, "[Pa·s]")
    R = check_positive("R", R, "[m]")
    return _scalar_or_array(u0 / np.sqrt(1.0 + 4.0 * u0**2 * p0 * t / (3.0 * eta * R**2)))


def flat_separation_reduced(u0, t, alpha):
    """Flat-surface Stefan law in the reduced units of the rough problem [h_rms]:

        ū(t) = ū0 [1 + 2 ū0² t / α]^{-1/2},

    ū0 in h_rms, t in τ = 3ηR²/(2α h_rms² p0) (eq. 6), i.e. eq. (10) with p_cont = 0; the
    same τ as the rough-surface curves (paper Fig. 2, blue lines).

    Parameters
    ----------
    u0 : array_like
        ū(0) [h_rms], > 0 (+inf allowed: ū = (α/2t)^{1/2}).
    t : array_like
        Time [τ], ≥ 0.
    alpha : array_like
        h_rms/u0 of law (3) [-] (enters through τ).
    """
    u0 = check_positive("u0", u0, "[h_rms]", allow_inf=True)
    t = check_positive("t", t, "[tau]", allow_zero=True)
    alpha = check_positive("alpha", alpha, "[-]")
    u0, t, alpha = np.broadcast_arrays(u0, t, alpha)
    with np.errstate(invalid="ignore", divide="ignore"):
        fin = np.isfinite(u0)
        out = np.where(fin, u0 / np.sqrt(1.0 + 2.0 * np.where(fin, u0, 0.0)**2 * t / alpha),
                       np.sqrt(alpha / (2.0 * t)))
    return _scalar_or_array(out)


# =========================================================================== inertia (Sec. 5)
def inertia_time_constant(D, rho, p0):
    """Inertial squeeze-out time constant τ' = (D² ρ / (64 p0))^{1/2} [s] — paper Sec. 5
    (flat surfaces, no viscosity, plug flow).

    Parameters
    ----------
    D : array_like
        Block diameter [m].
    rho : array_like
        Fluid density [kg/m³].
    p0 : array_like
        Squeezing pressure [Pa].

    Notes
    -----
    Example: D = 2 cm, ρ = 1000 kg/m³, p0 = 0.3 MPa → τ' = 1.4434e-4 s.
    """
    D = check_positive("D", D, "[m]")
    rho = check_positive("rho", rho, "[kg/m^3]")
    p0 = check_positive("p0", p0, "[Pa]")
    return _scalar_or_array(inertia_tau(D, rho, p0))


def inertia_tau(D, rho, p0):
    """τ' of :func:`inertia_time_constant` [s] for validated float64 arrays (no checks), into
    one new array of their broadcast shape (no temporaries)."""
    out = np.empty(np.broadcast_shapes(np.shape(D), np.shape(rho), np.shape(p0)))
    np.multiply(D, D, out=out)
    out *= rho
    out /= p0
    out *= 1.0 / 64.0
    return np.sqrt(out, out=out)


def inertia_squeeze_time(D, rho, p0, u_start, h_rms):
    """Inertia-limited squeeze-out time t* ≈ τ' ln(u(0)/h_rms) [s] — paper Sec. 5.

    Parameters
    ----------
    D, rho, p0 : array_like
        As in :func:`inertia_time_constant`: block diameter [m], fluid density [kg/m³],
        squeezing pressure [Pa].
    u_start : array_like
        Initial film thickness u(0) [m], > h_rms.
    h_rms : array_like
        Rms roughness [m].

    Notes
    -----
    Example: u(0) = 1 cm, h_rms = 0.3 mm, D = 2 cm, p0 = 0.3 MPa → t* ≈ 3.5 τ' ≈ 5e-4 s.
    """
    tau_p = inertia_time_constant(D, rho, p0)
    u_start = check_positive("u_start", u_start, "[m]")
    h_rms = check_positive("h_rms", h_rms, "[m]")
    u_start, h_rms = np.broadcast_arrays(u_start, h_rms)
    if np.any(u_start <= h_rms):
        i = np.flatnonzero((u_start <= h_rms).ravel())[0]
        raise ValueError(f"u_start = {float(u_start.ravel()[i])!r} is invalid: must be > h_rms = "
                         f"{float(h_rms.ravel()[i])!r} [m]")
    return _scalar_or_array(tau_p * np.log(u_start / h_rms))


def inertia_separation(t, u_start, D, rho, p0):
    """Inertia-limited film thickness u(t) = u(0) e^{-t/τ'} [m] — paper Sec. 5.

    Parameters
    ----------
    t : array_like
        Time [s], ≥ 0.
    u_start : array_like
        u(0) [m].
    D, rho, p0 : array_like
        As in :func:`inertia_time_constant`: block diameter [m], fluid density [kg/m³],
        squeezing pressure [Pa].
    """
    t = check_positive("t", t, "[s]", allow_zero=True)
    u_start = check_positive("u_start", u_start, "[m]")
    tau_p = inertia_time_constant(D, rho, p0)
    return _scalar_or_array(u_start * np.exp(-t / tau_p))


# =========================================================================== internals
def _scalar_or_array(x):
    x = np.asarray(x, dtype=np.float64)
    return float(x) if x.ndim == 0 else x
