"""Each flow theory beside a reference: errors of A, ū, σ_eff, flow stop and squeeze-out time.

Squeeze-out time propagation
----------------------------
For a cylindrical block of radius R pressed with p0, eqs. (18)+(19) of Lorenz & Persson (2010,
arXiv:1004.1037) give dū/dt = -(8 σ_eff(p_c)/R²)(p0 - p_c) with p_c = p_c(ū)
the contact pressure. The equation is autonomous, so the time is a quadrature; with p_c as the
variable (ū(p_c) is monotone),

    t(p_a → p_b) = (R²/8) ∫_{ln p_a}^{ln p_b} |dū/d ln p| / (σ_eff(p) (p0 - p)) d ln p,   (T1)

and t* ends at p_b = p_c(1.01 ū∞), ū∞ = ū(p0) (the definition of t* in Sec. 3 of Lorenz & Persson 2010). Each model — the reference
and every theory — enters (T1) with *its own* ū(p), dū/d ln p and σ_eff(p); the contact stage
starts at the reference's smallest pressure p_a (the time spent before it, at σ ∝ ū³ large, is
negligible: 96–100 % of t* is in the contact stage). The ratio t*_theory/t*_reference is
independent of R and η. The reference curves are interpolated monotonically (PCHIP of ū and of
ln σ_eff against ln p); a flow stop before p_b makes t* infinite (fluid trapped).
"""
from __future__ import annotations

import json
import math

import numpy as np

from .._core.io import atomic_path
from .._core.jsonable import json_default
from .._core.vocab import THEORIES

__all__ = ["compare_theories", "squeeze_time_ratio", "write_reference", "read_reference",
           "theory_sigma", "theory_flow_stop", "DEFAULT_VARIANTS"]

#: the theories as shipped (label, theory, options)
DEFAULT_VARIANTS = (
    ("average", "average", {}),
    ("critical_junction", "critical_junction", {}),
    ("emt", "emt", {}),
)
#: squeeze-out ends at ū = T_STAR_FACTOR · ū∞ (Lorenz & Persson 2010, Sec. 3)
T_STAR_FACTOR = 1.01
_N_T = 400


def _options(theory, opts):
    o = {"gamma": float(opts.get("gamma", 1.0))}
    if theory == "critical_junction":
        o["alpha_cj"] = float(opts.get("alpha_cj", 1.0))
        o["a_perc"] = float(opts.get("a_perc", 0.5))
    if theory == "emt":
        o["emt_threshold"] = float(opts.get("emt_threshold", 0.5))
    return o


def theory_sigma(psd, p, E_star, eta, theory, **opts):
    """σ_eff(p) [m³/(Pa·s)] of a theory with options (gamma, alpha_cj, a_perc, emt_threshold).

    The shipped kernels (:func:`fastcontact.conductivity.conductivity`) are used for every case
    they cover; a Bruggeman threshold other than 1/2 uses the generalized medium of
    :mod:`fastcontact.validation.emt`.
    """
    from .. import conductivity as cond

    o = _options(theory, opts)
    p = np.asarray(p, dtype=np.float64)
    if theory == "emt" and o["emt_threshold"] != 0.5:
        from .emt import emt_conductivity

        return emt_conductivity(psd, p, E_star, eta, threshold=o["emt_threshold"],
                                gamma=o["gamma"])
    kw = {k: v for k, v in o.items() if k != "emt_threshold"}
    sig, _ = cond.conductivity(psd, p, E_star, eta, theory, **kw)
    return np.asarray(sig, dtype=np.float64)


def theory_flow_stop(psd, E_star, theory, **opts):
    """Nominal pressure [Pa] at which a theory's flow stops (inf for the average theory)."""
    from .. import contact

    o = _options(theory, opts)
    if theory == "average":
        return math.inf
    a = o["a_perc"] if theory == "critical_junction" else o["emt_threshold"]
    return float(contact.percolation_pressure(psd, E_star, a))


def write_reference(df, path):
    """Write a reference DataFrame with its ``attrs`` (JSON in the Parquet metadata) [atomic]."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    table = pa.Table.from_pandas(df, preserve_index=False)
    meta = dict(table.schema.metadata or {})
    meta[b"fastcontact.reference"] = json.dumps(df.attrs, default=json_default).encode()
    table = table.replace_schema_metadata(meta)
    with atomic_path(path) as tmp:
        pq.write_table(table, tmp)


def read_reference(path):
    """Read a reference written by :func:`write_reference` (or a CSV with ``p0`` and columns)."""
    import pandas as pd
    import pyarrow.parquet as pq

    import os

    path = str(path)
    if not os.path.isfile(path):
        raise FileNotFoundError(f"reference = {path!r} is invalid: no such file (write one with "
                                f"'fastcontact bem reference' or write_reference)")
    if path.lower().endswith(".csv"):
        return pd.read_csv(path)
    table = pq.read_table(path)
    df = table.to_pandas()
    raw = (table.schema.metadata or {}).get(b"fastcontact.reference")
    df.attrs = json.loads(raw) if raw else {}
    return df


def reference_psd_and_modulus(reference, psd, E_star):
    """(psd, E* [Pa]) for a comparison or calibration: the reference's own PSD unless one is
    given; ValueError unless E* is finite and > 0."""
    if psd is None:
        psd = psd_from_reference(reference)
    E_star = float(E_star)
    if not (E_star > 0 and math.isfinite(E_star)):
        raise ValueError(f"E_star = {E_star!r} is invalid: must be finite and > 0 [Pa]")
    return psd, E_star


def psd_from_reference(reference):
    """The PSD recorded in a reference's provenance (``attrs["provenance"]["psd"]``)."""
    from ..psd import psd_from_dict

    d = reference.attrs.get("provenance", {}).get("psd")
    if not d:
        raise ValueError("reference is invalid: attrs['provenance']['psd'] is missing; pass the "
                         "PSD explicitly")
    return psd_from_dict(d)


def _curve_ref(ref, p0_col="p0"):
    """Monotone interpolants of the reference: ū(ln p), dū/d ln p, ln σ(ln p)."""
    from scipy.interpolate import PchipInterpolator

    lp = np.log(ref[p0_col].to_numpy(float))
    u = ref["u_mean"].to_numpy(float)
    s = ref["sigma_eff"].to_numpy(float)
    flow = s > 0
    fu = PchipInterpolator(lp, u, extrapolate=False)
    fs = PchipInterpolator(lp[flow], np.log(s[flow]), extrapolate=False) if flow.sum() >= 2 \
        else None
    lp_stop = float(np.log(ref.attrs["flow_stop_pressure"])) if np.isfinite(
        ref.attrs.get("flow_stop_pressure", math.nan)) else (lp[flow].max() if flow.any()
                                                              else -math.inf)
    lp_flow_max = lp[flow].max() if flow.any() else -math.inf
    return fu, fu.derivative(), fs, lp_stop, lp_flow_max, lp


def _t_integral(lp_a, lp_b, p0, dudlp, lnsig):
    """(T1) without the factor R²/8 on a graded ln p grid (clustered towards p_b ~ p0)."""
    if lp_b <= lp_a:
        return 0.0
    # y = -ln(p0 - p) is smooth to integrate; use nodes uniform in ln(p0 - p) near p0
    x = np.linspace(0.0, 1.0, _N_T)
    d_a = math.log(p0 - math.exp(lp_a))
    d_b = math.log(p0 - math.exp(lp_b))
    dd = d_a + (d_b - d_a) * x
    lp = np.log(p0 - np.exp(dd))
    lp = np.clip(np.concatenate([np.linspace(lp_a, lp[0], 50)[:-1], lp]), lp_a, lp_b)
    f = np.abs(dudlp(lp)) / (np.exp(lnsig(lp)) * (p0 - np.exp(lp)))
    return float(np.trapezoid(f, lp))


def squeeze_time_ratio(psd, E_star, reference, theory, p_apply=None, **opts):
    """t*_theory / t*_reference of the contact stage (T1) for applied pressures ``p_apply``.

    Returns an array (NaN where the reference does not cover the interval; inf where the
    theory traps the fluid and the reference does not; 0 where only the reference traps it).
    """
    from scipy.interpolate import PchipInterpolator
    from scipy.optimize import brentq

    from .. import contact

    eta = float(reference.attrs.get("eta", 1e-3))
    fu, fdu, fs, lp_stop, lp_flow_max, lp_ref = _curve_ref(reference)
    p_apply = reference["p0"].to_numpy(float) if p_apply is None else np.atleast_1d(p_apply)
    o = _options(theory, opts)
    lp_a = lp_ref[0]
    # theory curves on a fine grid up to the largest applied pressure
    lp_grid = np.linspace(lp_a - 0.1, math.log(p_apply.max()) + 0.05, 120)
    pg = np.exp(lp_grid)
    u_th = contact.mean_separation(psd, pg, E_star, gamma=o["gamma"])
    s_th = theory_sigma(psd, pg, E_star, eta, theory, **o)
    stop_th = theory_flow_stop(psd, E_star, theory, **o)
    pos = s_th > 0
    fu_th = PchipInterpolator(lp_grid, u_th)
    fdu_th = fu_th.derivative()
    fs_th = PchipInterpolator(lp_grid[pos], np.log(s_th[pos])) if pos.sum() >= 2 else None
    out = np.full(p_apply.shape, math.nan)
    for i, pa in enumerate(p_apply):
        lpa = math.log(pa)
        if lpa <= lp_a:
            continue

        def end(fuu):
            target = T_STAR_FACTOR * float(fuu(lpa))
            return brentq(lambda y: float(fuu(y)) - target, lp_a - 0.1 if fuu is fu_th else lp_a,
                          lpa)

        try:
            lpb_ref = end(fu)
        except ValueError:
            continue
        lpb_th = end(fu_th)
        ref_trapped = lpb_ref > lp_flow_max or fs is None
        th_trapped = math.exp(lpb_th) >= stop_th or fs_th is None
        if ref_trapped and th_trapped:
            continue
        if ref_trapped:
            out[i] = 0.0
            continue
        if th_trapped:
            out[i] = math.inf
            continue
        t_ref = _t_integral(lp_a, lpb_ref, pa, fdu, fs)
        t_th = _t_integral(lp_a, lpb_th, pa, fdu_th, fs_th)
        out[i] = t_th / t_ref
    return out


def _rel(th, ref):
    th = np.asarray(th, dtype=float)
    ref = np.asarray(ref, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = th / ref - 1.0
    r = np.where((ref == 0) & (th == 0), 0.0, r)
    return np.where((ref == 0) & (th > 0), math.inf, r)


#: units of the columns of :func:`compare_theories`
_COMPARISON_UNITS = {"p0": "Pa", "u_ref": "m", "u_th": "m", "sigma_ref": "m^3/(Pa s)",
                     "sigma_th": "m^3/(Pa s)", "area_ref": "1", "area_th": "1", "area_err": "1",
                     "u_err": "1", "sigma_err": "1", "t_ratio": "1"}


def _variant_columns(psd, E_star, eta, reference, p, a_th, theory, o, squeeze):
    """One variant's columns of :func:`compare_theories` at the pressures ``p`` [Pa]: each
    quantity's theory value (``a_th``: A/A0, the same for every variant), and where the
    reference has it, the reference value and the relative error; ``t_ratio`` (T1)."""
    from .. import contact

    d = {"area_th": a_th}
    if "area_fraction" in reference:
        d["area_ref"] = reference["area_fraction"].to_numpy(float)
        d["area_err"] = _rel(a_th, d["area_ref"])
    u_th = contact.mean_separation(psd, p, E_star, gamma=o["gamma"])
    d["u_th"] = u_th
    if "u_mean" in reference:
        d["u_ref"] = reference["u_mean"].to_numpy(float)
        d["u_err"] = _rel(u_th, d["u_ref"])
    s_th = theory_sigma(psd, p, E_star, eta, theory, **o)
    d["sigma_th"] = s_th
    if "sigma_eff" in reference:
        d["sigma_ref"] = reference["sigma_eff"].to_numpy(float)
        d["sigma_err"] = _rel(s_th, d["sigma_ref"])
    if squeeze and {"u_mean", "sigma_eff"} <= set(reference.columns):
        d["t_ratio"] = squeeze_time_ratio(psd, E_star, reference, theory, p, **o)
    return d


def compare_theories(psd, E_star, reference, *, variants=None, calibration=None, squeeze=True):
    """Every theory (with its options) beside a reference: relative errors per pressure.

    Parameters
    ----------
    psd : fastcontact PSD or None
        Roughness spectrum; None = the PSD in ``reference.attrs["provenance"]["psd"]``.
    E_star : float
        Contact modulus E* [Pa].
    reference : pandas.DataFrame
        A reference from :func:`bem_reference` (or measured data with ``p0`` [Pa] and any of
        ``area_fraction``, ``u_mean`` [m], ``sigma_eff`` [m³/(Pa·s)] at ``attrs["eta"]``).
    variants : sequence of (label, theory, options), optional
        Theories to compare; default the three as shipped (``DEFAULT_VARIANTS``). Options:
        ``gamma``, ``alpha_cj``, ``a_perc``, ``emt_threshold``.
    calibration : Calibration, optional
        Adds the three theories with the calibrated constants (labels ``*+cal``).
    squeeze : bool
        Also compute the propagated squeeze-out time ratio t*_theory/t*_reference (T1).

    Returns
    -------
    pandas.DataFrame
        One row per (variant, pressure): ``label``, ``theory``, ``p0`` [Pa], ``area_ref``,
        ``area_th``, ``area_err``, ``u_ref`` [m], ``u_th`` [m], ``u_err``, ``sigma_ref``,
        ``sigma_th`` [m³/(Pa·s)], ``sigma_err`` (relative errors th/ref - 1; inf where only the
        reference has stopped the flow), ``t_ratio``. ``attrs["flow_stop"]``: per label the
        theory's and the reference's flow-stop pressure [Pa] and their ratio.
    """
    import pandas as pd

    from .. import contact

    psd, E_star = reference_psd_and_modulus(reference, psd, E_star)
    if "p0" not in reference:
        raise ValueError("reference is invalid: it needs a 'p0' column [Pa]")
    variants = list(DEFAULT_VARIANTS if variants is None else variants)
    if calibration is not None:
        for th in THEORIES:
            variants.append((f"{th}+cal", th, calibration.options(th)))
    eta = float(reference.attrs.get("eta", 1e-3))
    p = reference["p0"].to_numpy(float)
    stop_ref = float(reference.attrs.get("flow_stop_pressure", math.nan))
    a_th = contact.area_fraction(psd, p, E_star)
    rows = []
    stops = {}
    for label, theory, opts in variants:
        o = _options(theory, opts)
        d = {"label": np.full(p.size, label), "theory": np.full(p.size, theory), "p0": p}
        d.update(_variant_columns(psd, E_star, eta, reference, p, a_th, theory, o, squeeze))
        rows.append(pd.DataFrame(d))
        st = theory_flow_stop(psd, E_star, theory, **o)
        stops[label] = {"theory": st, "reference": stop_ref,
                        "ratio": st / stop_ref if np.isfinite(stop_ref) else math.nan,
                        "options": o}
    out = pd.concat(rows, ignore_index=True)
    out.attrs = {"flow_stop": stops, "E_star": E_star, "eta": eta,
                 "reference_provenance": reference.attrs.get("provenance", {}),
                 "units": dict(_COMPARISON_UNITS)}
    return out
