"""Joint calibration of the theory's constants (γ, α_cj, a_perc, Bruggeman threshold).

The shipped theory has four constants that no first-principles argument fixes:

- γ, the Yang–Persson factor of ū(ζ) and u1(ζ) (C. Yang & B.N.J. Persson, J. Phys.: Condens.
  Matter 20, 215214 (2008), doi:10.1088/0953-8984/20/21/215214), default 1 (paper's A4);
- α_cj and a_perc of the critical-junction theory (Lorenz & Persson 2010,
  arXiv:1004.1037, eqs. 31–32), defaults 1 and 0.5;
- the percolation threshold A_c of the generalized Bruggeman medium
  (:mod:`fastcontact.validation.emt`; Kirkpatrick, doi:10.1103/RevModPhys.45.574), default 1/2.

:func:`calibrate` fits them *jointly* by nonlinear least squares (scipy ``least_squares``,
trust-region reflective, bounded) on the residual vector

    r = [ ln(ū_th/ū_ref)                       at each pressure           (u)
          ln(s_th/s_ref), s = -Δū/Δln p         between adjacent pressures (u_slope)
          ln(σ_cj/σ_ref), ln(σ_emt/σ_ref)       where the reference flows   (sigma_cj, sigma_emt)
          w ln(p_stop,th/p_stop,ref)            cj and emt, w = √(#σ rows)  (stop_cj, stop_emt) ]

(log residuals clipped at ±``CLIP``: a theory that has already stopped the flow where the
reference still flows contributes -CLIP). The average-separation σ_eff has no constant of its
own and is not fitted (γ is set by ū). Whatever the reference lacks fixes nothing: a
constant no residual depends on keeps its default and is not listed in ``fitted``.
"""
from __future__ import annotations

import dataclasses
import json
import math

import numpy as np

from .._core.io import write_bytes_atomic
from .._core.jsonable import json_plain

__all__ = ["Calibration", "calibrate", "residuals", "PARAMETERS", "BOUNDS", "DEFAULTS"]

PARAMETERS = ("gamma", "alpha_cj", "a_perc", "emt_threshold")
DEFAULTS = {"gamma": 1.0, "alpha_cj": 1.0, "a_perc": 0.5, "emt_threshold": 0.5}
BOUNDS = {"gamma": (0.1, 1.0), "alpha_cj": (0.05, 3.0), "a_perc": (0.05, 0.95),
          "emt_threshold": (0.05, 0.95)}
CLIP = 8.0


@dataclasses.dataclass(frozen=True)
class Calibration:
    """Calibrated constants of the theory (see :func:`calibrate`).

    Attributes
    ----------
    gamma : float
        Yang–Persson factor [-] of ū(ζ), u1(ζ).
    alpha_cj : float
        Critical-junction factor multiplying u1(ζc) [-] (σ_eff carries α_cj³).
    a_perc : float
        Critical-junction percolation area fraction [-].
    emt_threshold : float
        Contact-area fraction at which the generalized Bruggeman flow stops [-].
    fitted : tuple of str
        The constants the reference constrained (the others are at their defaults).
    residuals_before, residuals_after : dict
        RMS log residual per group (u, u_slope, sigma_cj, sigma_emt, stop_cj, stop_emt) with
        the defaults and with the fitted constants.
    provenance : dict
        The reference's provenance and the fit's own record (cost, evaluations).
    """

    gamma: float = 1.0
    alpha_cj: float = 1.0
    a_perc: float = 0.5
    emt_threshold: float = 0.5
    fitted: tuple = ()
    residuals_before: dict = dataclasses.field(default_factory=dict)
    residuals_after: dict = dataclasses.field(default_factory=dict)
    provenance: dict = dataclasses.field(default_factory=dict)

    def __post_init__(self):
        for name in PARAMETERS:
            v = getattr(self, name)
            lo, hi = (0.0, 1.0) if name != "alpha_cj" else (0.0, math.inf)
            if not (isinstance(v, (int, float)) and lo < v <= hi and math.isfinite(v)) or \
                    (name in ("a_perc", "emt_threshold") and v >= 1.0):
                raise ValueError(f"{name} = {v!r} is invalid: must lie in "
                                 f"{'(0, 1]' if name == 'gamma' else '(0, 1)' if lo == 0.0 and hi == 1.0 else '(0, inf)'}")
        object.__setattr__(self, "fitted", tuple(self.fitted))

    def options(self, theory):
        """Keyword options of ``theory`` with these constants (for compare/conductivity)."""
        o = {"gamma": self.gamma}
        if theory == "critical_junction":
            o.update(alpha_cj=self.alpha_cj, a_perc=self.a_perc)
        if theory == "emt":
            o["emt_threshold"] = self.emt_threshold
        return o

    def to_dict(self):
        return dataclasses.asdict(self) | {"fitted": list(self.fitted)}

    @classmethod
    def from_dict(cls, d):
        known = {f.name for f in dataclasses.fields(cls)}
        extra = set(d) - known
        if extra:
            raise ValueError(f"calibration keys {sorted(extra)} are invalid: valid keys are "
                             f"{sorted(known)}")
        d = dict(d)
        d["fitted"] = tuple(d.get("fitted", ()))
        return cls(**d)

    def to_json(self, path=None):
        """JSON text (written atomically to ``path`` if given)."""
        return _emit(json.dumps(self.to_dict(), indent=2, default=json_plain, allow_nan=True),
                     path)

    @classmethod
    def from_json(cls, source):
        """From JSON text or a path to a JSON file."""
        text = _read_text(source)
        return cls.from_dict(json.loads(text))

    def to_toml(self, path=None):
        """TOML text: the four constants at top level, the rest in tables (JSON-encoded
        provenance, since TOML has no null) — written atomically to ``path`` if given."""
        lines = ["# fastcontact calibration (issue 13): constants of the theory", ""]
        for name in PARAMETERS:
            lines.append(f"{name} = {float(getattr(self, name))!r}")
        lines.append(f"fitted = {json.dumps(list(self.fitted))}")
        lines.append(f"provenance_json = {json.dumps(json.dumps(self.provenance, default=json_plain))}")
        for tab in ("residuals_before", "residuals_after"):
            lines += ["", f"[{tab}]"]
            for k, v in getattr(self, tab).items():
                v = float(v)
                lines.append(f"{k} = {'nan' if math.isnan(v) else repr(v)}")
        return _emit("\n".join(lines) + "\n", path)

    @classmethod
    def from_toml(cls, source):
        """From TOML text or a path to a TOML file written by :meth:`to_toml`."""
        try:
            import tomllib
        except ModuleNotFoundError:  # Python 3.10
            import tomli as tomllib

        d = tomllib.loads(_read_text(source))
        d["provenance"] = json.loads(d.pop("provenance_json", "{}"))
        return cls.from_dict(d)


def _read_text(source):
    import os

    s = str(source)
    if "\n" not in s and os.path.exists(s):
        with open(s, encoding="utf-8") as f:
            return f.read()
    return s


def _emit(text, path):
    """``text``, written atomically (UTF-8) to ``path`` first if one is given."""
    if path is not None:
        write_bytes_atomic(path, text.encode("utf-8"))
    return text


def _clip_log(th, ref):
    th = np.asarray(th, dtype=float)
    ref = np.asarray(ref, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.log(th / ref)
    r = np.where(th <= 0, -CLIP, r)
    return np.clip(r, -CLIP, CLIP)


def residuals(psd, E_star, reference, params, theories=("critical_junction", "emt")):
    """Residual groups (dict of arrays) of the constants ``params`` against ``reference``.

    ``theories`` selects the flow theories whose σ_eff and flow stop enter."""
    from .. import contact
    from .compare import theory_flow_stop, theory_sigma

    prm = dict(DEFAULTS) | dict(params)
    p = reference["p0"].to_numpy(float)
    eta = float(reference.attrs.get("eta", 1e-3))
    out = {}
    if "u_mean" in reference:
        u_ref = reference["u_mean"].to_numpy(float)
        ok = np.isfinite(u_ref) & (u_ref > 0)
        u_th = contact.mean_separation(psd, p, E_star, gamma=prm["gamma"])
        out["u"] = _clip_log(u_th[ok], u_ref[ok])
        if ok.sum() >= 2:
            lp = np.log(p[ok])
            s_ref = -np.diff(u_ref[ok]) / np.diff(lp)
            s_th = -np.diff(u_th[ok]) / np.diff(lp)
            good = s_ref > 0
            out["u_slope"] = _clip_log(s_th[good], s_ref[good])
    stop_ref = float(reference.attrs.get("flow_stop_pressure", math.nan))
    n_sig = 1
    if "sigma_eff" in reference:
        s_ref = reference["sigma_eff"].to_numpy(float)
        flow = np.isfinite(s_ref) & (s_ref > 0)
        n_sig = max(int(flow.sum()), 1)
        if flow.any():
            for key, th in (("sigma_cj", "critical_junction"), ("sigma_emt", "emt")):
                if th not in theories:
                    continue
                s_th = theory_sigma(psd, p[flow], E_star, eta, th, **prm)
                out[key] = _clip_log(s_th, s_ref[flow])
    if np.isfinite(stop_ref) and stop_ref > 0:
        w = math.sqrt(n_sig)
        for key, th in (("stop_cj", "critical_junction"), ("stop_emt", "emt")):
            if th not in theories:
                continue
            out[key] = np.array([w * math.log(theory_flow_stop(psd, E_star, th, **prm) / stop_ref)])
    return out


def _rms(groups):
    return {k: float(np.sqrt(np.mean(v ** 2))) if v.size else math.nan for k, v in groups.items()}


def _which(reference, theories):
    have_u = "u_mean" in reference
    have_s = "sigma_eff" in reference and bool((reference["sigma_eff"] > 0).any())
    have_stop = np.isfinite(float(reference.attrs.get("flow_stop_pressure", math.nan)))
    fit = []
    if have_u or have_s:
        fit.append("gamma")
    if have_s and "critical_junction" in theories:
        fit.append("alpha_cj")
    if (have_s or have_stop) and "critical_junction" in theories:
        fit.append("a_perc")
    if (have_s or have_stop) and "emt" in theories:
        fit.append("emt_threshold")
    return fit


def calibrate(psd, E_star, reference, *, fit=None, initial=None,
              theories=("critical_junction", "emt")):
    """Fit γ, α_cj, a_perc and the Bruggeman threshold jointly to a reference.

    Parameters
    ----------
    psd : fastcontact PSD or None
        Roughness spectrum; None = the PSD recorded in the reference's provenance.
    E_star : float
        Contact modulus E* [Pa].
    reference : pandas.DataFrame
        ``p0`` [Pa] and any subset of ``u_mean`` [m], ``sigma_eff`` [m³/(Pa·s)] (viscosity
        ``attrs["eta"]`` [Pa·s], default 1e-3) and ``attrs["flow_stop_pressure"]`` [Pa] — from
        :func:`bem_reference` or measured (separations, leak rates converted to σ_eff).
    fit : sequence of str, optional
        Constants to fit (subset of ``PARAMETERS``); default every constant the reference
        constrains. The others stay at ``initial`` or their defaults.
    initial : dict, optional
        Starting values (defaults γ = 1, α_cj = 1, a_perc = 0.5, threshold = 0.5).
    theories : sequence of {"critical_junction", "emt"}
        Flow theories whose σ_eff and flow stop enter the fit (default both).

    Returns
    -------
    Calibration
        Frozen dataclass with the fitted constants, the RMS residual per group before (shipped
        defaults) and after, and the reference's provenance.
    """
    from scipy.optimize import least_squares

    from .compare import reference_psd_and_modulus

    psd, E_star = reference_psd_and_modulus(reference, psd, E_star)
    if "p0" not in reference or len(reference) == 0:
        raise ValueError("reference is invalid: it needs a non-empty 'p0' column [Pa]")
    start = dict(DEFAULTS) | dict(initial or {})
    theories = tuple(theories)
    for th in theories:
        if th not in ("critical_junction", "emt"):
            raise ValueError(f"theories entry {th!r} is invalid: must be 'critical_junction' "
                             f"or 'emt'")
    names = list(_which(reference, theories) if fit is None else fit)
    for nme in names:
        if nme not in PARAMETERS:
            raise ValueError(f"fit entry {nme!r} is invalid: must be one of {list(PARAMETERS)}")
    before = residuals(psd, E_star, reference, DEFAULTS, theories)
    if not before:
        raise ValueError("reference is invalid: it has none of 'u_mean', 'sigma_eff', "
                         "attrs['flow_stop_pressure'] to fit to")
    lo = np.array([BOUNDS[k][0] for k in names])
    hi = np.array([BOUNDS[k][1] for k in names])
    x0 = np.clip(np.array([start[k] for k in names], dtype=float), lo + 1e-9, hi - 1e-9)

    def vec(x):
        g = residuals(psd, E_star, reference, start | dict(zip(names, x)), theories)
        return np.concatenate([v for v in g.values()])

    sol = None
    final = dict(start)
    if names:
        sol = least_squares(vec, x0, bounds=(lo, hi), method="trf", diff_step=1e-4,
                            x_scale=np.maximum(np.abs(x0), 0.1), xtol=1e-8, ftol=1e-10,
                            max_nfev=400)
        final |= dict(zip(names, (float(v) for v in sol.x)))
    after = residuals(psd, E_star, reference, final, theories)
    prov = {"reference": reference.attrs.get("provenance", {}),
            "reference_flow_stop_pressure": reference.attrs.get("flow_stop_pressure"),
            "E_star": E_star, "eta": float(reference.attrs.get("eta", 1e-3)),
            "n_pressures": int(len(reference)), "theories": list(theories),
            "least_squares": None if sol is None else {"cost": float(sol.cost),
                                                       "nfev": int(sol.nfev),
                                                       "status": int(sol.status)}}
    return Calibration(gamma=min(final["gamma"], 1.0), alpha_cj=final["alpha_cj"],
                       a_perc=final["a_perc"], emt_threshold=final["emt_threshold"],
                       fitted=tuple(names), residuals_before=_rms(before),
                       residuals_after=_rms(after), provenance=prov)
