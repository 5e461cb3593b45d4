"""The tables' large-separation tail: σ̄ above the table top, fitted to direct samples.

Above the largest tabulated separation (ū ≈ 32 h_rms) the flow is that of a nearly flat film:
σ̄ → (ū/h_rms)³ (Lorenz & Persson 2010, Sec. 3; arXiv:1004.1037), with corrections of
relative order (h_rms/ū)² that depend on the theory (critical junction: σ̄ = (v + δ)³, δ the
constant u1(ζc) - ū; effective medium: σ̄/v³ - 1 ≈ -2.2/v², no closed form). Precompute
stores direct ū and σ̄ below the table (``info["tail"]``); :func:`fit_tail` fits
σ̄^(1/3) = v + g(1/v) to them, g a polynomial, and the closed form σ̄ = y³ - c y, y = v + d,
takes over only where it is within :data:`TAIL_TOL` of the fit.
"""
from __future__ import annotations

import numpy as np

__all__ = ["fit_tail", "TAIL_TOL", "TAIL_DEGREE"]

#: the closed-form tail starts where it is within TAIL_TOL (relative σ̄) of the fitted tail
#: everywhere above (v_ext grows by TAIL_GROWTH until it is)
TAIL_TOL = 1e-8
TAIL_GROWTH = 1.25
#: degree of the tail's polynomial g(h_rms/ū) fitted to the tables' tail samples
TAIL_DEGREE = 5


def fit_tail(samples, theory, v_top, sig_top, v_ext):
    """The tail fitted to the tables' tail samples: σ̄^(1/3) = v + g0 + g(1/v), g a polynomial
    of degree TAIL_DEGREE in 1/v (least squares; the table top weighted 1e3, so continuous
    to ~1e-10), and the closed form σ̄ = y³ - c y, y = v + g0, above v_ext, with c matched to
    the fit at v_ext and v_ext raised until the two agree to TAIL_TOL everywhere above.

    "average" is σ̄ = v³ exactly (no fit). The fit's worst relative σ̄ residual on the
    samples goes into ``fit_error`` (~1e-10 on the embedded tables).

    Parameters
    ----------
    samples : dict
        The tables' ``info["tail"]`` (:func:`fastcontact.tables.build.precompute`).
    theory : str
        Flow theory whose σ̄ samples are fitted.
    v_top, sig_top : float
        ū/h_rms [-] and σ̄ [-] at the table top (the lowest tabulated pressure).
    v_ext : float
        Lowest separation [h_rms] at which the closed form may start.

    Returns
    -------
    dict
        c, d (closed form σ̄ = y³ - c y, y = v + d, above ``v_ext``), cn = 0 and g1..g5 (the
        fit σ̄ = (v + d + Σ g_k v^-k)³ between the top and v_ext), v_ext [h_rms], fit_error.
    """
    if theory == "average":
        return dict(c=0.0, d=0.0, cn=0.0, g1=0.0, g2=0.0, g3=0.0, g4=0.0, g5=0.0, v_ext=v_ext,
                    fit_error=0.0)
    v = np.concatenate(([v_top], np.asarray(samples["u_over_h"], dtype=np.float64)))
    sig = np.concatenate(([sig_top], np.asarray(samples["sigma_bar"][theory], dtype=np.float64)))
    x = 1.0 / v
    g = np.cbrt(sig) - v
    deg = int(min(TAIL_DEGREE, v.size - 2))
    w = np.ones(v.size)
    w[0] = 1e3
    A = np.vander(x, deg + 1, increasing=True)
    coef = np.linalg.lstsq(A * w[:, None], g * w, rcond=None)[0]
    coef = np.concatenate((coef, np.zeros(TAIL_DEGREE + 1 - coef.size)))
    fit_error = float(np.max(np.abs((v + A @ coef[:deg + 1]) ** 3 / sig - 1.0)))
    d = float(coef[0])

    def near(vv):
        return (vv + np.polynomial.polynomial.polyval(1.0 / vv, coef)) ** 3

    for _ in range(200):
        y = v_ext + d
        c = float((y ** 3 - near(v_ext)) / y)
        vv = np.geomspace(v_ext, 1e6 * v_ext, 2000)
        yy = vv + d
        if np.max(np.abs((yy ** 3 - c * yy) / near(vv) - 1.0)) < TAIL_TOL:
            break
        v_ext *= TAIL_GROWTH
    return dict(c=c, d=d, cn=0.0, g1=float(coef[1]), g2=float(coef[2]), g3=float(coef[3]),
                g4=float(coef[4]), g5=float(coef[5]), v_ext=float(v_ext), fit_error=fit_error)
