"""Surface roughness power spectra C(q) in the Persson convention.

Glossary
--------
q        wavevector magnitude [1/m]
q0, q1   smallest / largest wavevector of the roughness [1/m]
q_roll   roll-off wavevector: C is flat on [q0, q_roll) [1/m]
C(q)     isotropic 2-D power spectrum, Persson convention [m^4]:
         C(q) = (2π)^-2 ∫ d²x <h(x)h(0)> exp(-iq·x)
h_rms    root-mean-square roughness, h_rms² = 2π ∫ q C dq [m]
ξ        rms slope, ξ² = 2π ∫ q³ C dq [-]
H        Hurst exponent, C ∝ q^(-2(1+H)) on the self-affine branch [-]

Every spectrum here is represented exactly as a *piecewise power law*: on segment i,
``C(q) = c[i] * (q / qb[i]) ** e[i]`` for ``qb[i] <= q <= qb[i+1]``. A self-affine spectrum
with roll-off is two such segments; a tabulated spectrum is the log-log linear interpolant of
its samples. This makes every moment ∫ q^n C dq a closed form, evaluated without cancellation
(``expm1``/``log1p``), which the contact-mechanics quadrature relies on near its singular
lower limit.

Convention trap: SurfaceTopography / contact.engineering publish ``C_ST = (2π)² C_Persson``.
:class:`TabulatedPSD` takes the convention explicitly and stores Persson-convention C in SI.
"""
from __future__ import annotations

import hashlib
import json
import math

import numpy as np

from .._core.validate import as_float_array, check_positive, check_range
from .._core.vocab import CONVENTIONS
from ..kernels.powerlaw import seg_moment_np

__all__ = ["PSD", "SelfAffinePSD", "TabulatedPSD", "CONVENTIONS", "psd_from_dict"]


class PSD:
    """A piecewise power-law isotropic power spectrum C(q) [m^4] on [q0, q1] (Persson).

    Subclasses set ``qb`` (breakpoints, increasing, ``qb[0] = q0``, ``qb[-1] = q1`` [1/m]),
    ``c`` (C at the start of each segment [m^4]) and ``e`` (log-log slope of each segment).
    ``kinks`` lists the breakpoints where the slope changes by a finite amount that a
    quadrature must respect as a panel boundary.
    """

    qb: np.ndarray
    c: np.ndarray
    e: np.ndarray
    kinks: tuple = ()

    def _finish(self):
        self.qb = np.ascontiguousarray(self.qb, dtype=np.float64)
        self.c = np.ascontiguousarray(self.c, dtype=np.float64)
        self.e = np.ascontiguousarray(self.e, dtype=np.float64)
        # cumulative ∫_{q0}^{qb[j]} q^n C dq for n = 1, 3 at the breakpoints
        self.cum1 = self._cumulative(1.0)
        self.cum3 = self._cumulative(3.0)

    def _cumulative(self, n):
        out = np.zeros(self.qb.size)
        for i in range(self.c.size):
            out[i + 1] = out[i] + float(seg_moment_np(self.c[i], self.qb[i], self.e[i], n,
                                                      self.qb[i], self.qb[i + 1]))
        return out

    # ------------------------------------------------------------------ basic properties
    @property
    def q0(self) -> float:
        """Smallest wavevector [1/m]."""
        return float(self.qb[0])

    @property
    def q1(self) -> float:
        """Largest wavevector [1/m]."""
        return float(self.qb[-1])

    @property
    def zeta1(self) -> float:
        """Largest magnification ζ1 = q1/q0 [-]."""
        return self.q1 / self.q0

    @property
    def h_rms(self) -> float:
        """Root-mean-square roughness, h_rms² = 2π ∫ q C dq [m]."""
        return math.sqrt(2.0 * math.pi * self.cum1[-1])

    @property
    def rms_slope(self) -> float:
        """Root-mean-square slope ξ, ξ² = 2π ∫ q³ C dq [-]."""
        return math.sqrt(2.0 * math.pi * self.cum3[-1])

    def __call__(self, q):
        """C(q) [m^4] at wavevector(s) q [1/m]; 0 outside [q0, q1]."""
        q = np.asarray(q, dtype=np.float64)
        i = np.clip(np.searchsorted(self.qb, q, side="right") - 1, 0, self.c.size - 1)
        with np.errstate(divide="ignore", invalid="ignore"):
            val = self.c[i] * (q / self.qb[i]) ** self.e[i]
        return np.where((q >= self.q0) & (q <= self.q1), val, 0.0)

    def moment(self, n: float, a=None, b=None):
        """∫_a^b q^n C(q) dq over [a, b] ∩ [q0, q1] (defaults: the whole spectrum)."""
        a = self.q0 if a is None else a
        b = self.q1 if b is None else b
        a_arr, b_arr = np.broadcast_arrays(np.asarray(a, float), np.asarray(b, float))
        out = np.zeros(a_arr.shape)
        for i in range(self.c.size):
            lo = np.clip(a_arr, self.qb[i], self.qb[i + 1])
            hi = np.clip(b_arr, self.qb[i], self.qb[i + 1])
            m = hi > lo
            if np.any(m):
                out[m] += seg_moment_np(self.c[i], self.qb[i], self.e[i], float(n), lo[m], hi[m])
        return out if out.ndim else float(out)

    def h_rms_above(self, zeta):
        """Roughness above magnification ζ: h_rms(ζ)² = 2π ∫_{ζq0}^{q1} q C dq [m]."""
        return np.sqrt(2.0 * math.pi * np.asarray(self.moment(1.0, np.asarray(zeta) * self.q0, self.q1)))

    def kernel_arrays(self):
        """(qb, c, e, cum3) as contiguous float64 arrays for the numba kernels."""
        return self.qb, self.c, self.e, self.cum3

    def restricted(self, q_min: float) -> "TabulatedPSD":
        """The spectrum restricted to q >= q_min [1/m] (asperity-scale problems)."""
        check_range("q_min", q_min, self.q0, self.q1, "[1/m]", hi_open=True)
        j = int(np.searchsorted(self.qb, q_min, side="right"))
        qb = np.concatenate(([q_min], self.qb[j:]))
        c0 = float(self(q_min))
        c = np.concatenate(([c0], self.c[j:]))
        e = np.concatenate(([self.e[j - 1]], self.e[j:]))
        out = PiecewisePowerLawPSD(qb, c, e, kinks=tuple(k for k in self.kinks if k > q_min))
        return out

    # ------------------------------------------------------------------ provenance
    def to_dict(self) -> dict:
        """A JSON-serialisable definition that :func:`psd_from_dict` rebuilds exactly."""
        raise NotImplementedError

    def fingerprint(self) -> str:
        """SHA-256 of the canonical JSON definition (used to match tables to surfaces)."""
        blob = json.dumps(self.to_dict(), sort_keys=True, separators=(",", ":")).encode()
        return hashlib.sha256(blob).hexdigest()

    def __repr__(self):
        return (f"{type(self).__name__}(h_rms={self.h_rms:.4g} m, q0={self.q0:.4g} 1/m, "
                f"q1={self.q1:.4g} 1/m, rms_slope={self.rms_slope:.4g})")


class PiecewisePowerLawPSD(PSD):
    """A spectrum given directly by its power-law segments (see :class:`PSD`)."""

    def __init__(self, qb, c, e, kinks=()):
        self.qb, self.c, self.e = (np.asarray(x, dtype=np.float64) for x in (qb, c, e))
        self.kinks = tuple(float(k) for k in kinks)
        self._finish()

    def to_dict(self):
        return {"kind": "piecewise_power_law", "qb": self.qb.tolist(), "c": self.c.tolist(),
                "e": self.e.tolist(), "kinks": list(self.kinks)}


class SelfAffinePSD(PSD):
    """Self-affine spectrum with optional roll-off.

    ``C = C0 q_roll^(-2(1+H))`` on [q0, q_roll), ``C = C0 q^(-2(1+H))`` on [q_roll, q1], 0 elsewhere,
    with C0 fixed by the requested ``h_rms``.

    Parameters
    ----------
    h_rms : float [m]
        Root-mean-square roughness, > 0 (a length quantity, e.g. pint ``Q_(10, "um")``, is
        converted).
    hurst : float [-]
        Hurst exponent H, in (0, 1).
    q0 : float [1/m]
        Smallest wavevector, > 0.
    q1 : float [1/m]
        Largest wavevector, > q0.
    q_roll : float [1/m], optional
        Roll-off wavevector in [q0, q1); None (default): no roll-off.

    References
    ----------
    B.N.J. Persson, O. Albohr, U. Tartaglino, A.I. Volokitin, E. Tosatti, J. Phys.: Condens.
    Matter 17, R1 (2005), doi:10.1088/0953-8984/17/1/R01 (self-affine spectra with roll-off);
    B. Lorenz & B.N.J. Persson, Eur. Phys. J. E 32, 281 (2010), App. A,
    arXiv:1004.1037 (the convention of C).
    """

    def __init__(self, h_rms, hurst, q0, q1, q_roll=None):
        self.h_rms_target = float(check_positive("h_rms", h_rms, "[m]"))
        self.hurst = float(check_range("hurst", hurst, 0.0, 1.0, "[-]", lo_open=True, hi_open=True))
        q0 = float(check_positive("q0", q0, "[1/m]"))
        q1 = float(check_positive("q1", q1, "[1/m]"))
        if not q1 > q0:
            raise ValueError(f"q1 = {q1!r} is invalid: must be > q0 = {q0!r} [1/m]")
        if q_roll is not None:
            q_roll = float(check_range("q_roll", q_roll, q0, q1, "[1/m]", hi_open=True))
            if q_roll == q0:
                q_roll = None
        self.q_roll = q_roll
        slope = -2.0 * (1.0 + self.hurst)
        if q_roll is None:
            qb, c, e, kinks = [q0, q1], [q0 ** slope], [slope], ()
        else:
            qb, c, e, kinks = [q0, q_roll, q1], [q_roll ** slope, q_roll ** slope], [0.0, slope], (q_roll,)
        # scale to unit C0 first, then fix C0 from h_rms
        self.qb, self.c, self.e, self.kinks = np.array(qb), np.array(c), np.array(e), kinks
        self._finish()
        self.C0 = self.h_rms_target ** 2 / (2.0 * math.pi * self.cum1[-1])  # [m^4 m^(-2(1+H))]
        self.c = self.c * self.C0
        self._finish()

    def to_dict(self):
        return {"kind": "self_affine", "h_rms": self.h_rms_target, "hurst": self.hurst,
                "q0": self.q0, "q1": self.q1, "q_roll": self.q_roll}

    def __repr__(self):
        return (f"SelfAffinePSD(h_rms={self.h_rms_target!r}, hurst={self.hurst!r}, q0={self.q0!r}, "
                f"q1={self.q1!r}, q_roll={self.q_roll!r})")


class TabulatedPSD(PSD):
    """A measured spectrum given as samples, interpolated linearly in log C against log q.

    Parameters
    ----------
    q : array_like [1/m]
        Wavevectors, 1-D, strictly increasing, > 0, at least 2 (a 2-D array is refused,
        never flattened; masked elements are refused).
    C : array_like [m^4]
        Spectrum at ``q``, same shape, finite and > 0, in the stated ``convention``.
    convention : {"persson", "surface_topography"}
        ``"surface_topography"`` (SurfaceTopography / contact.engineering) is (2π)² times
        Persson's C (T.D.B. Jacobs, T. Junge, L. Pastewka, Surf. Topogr. Metrol. Prop. 5,
        013001 (2017), doi:10.1088/2051-672X/aa51f8); it is converted here, and the object
        always holds Persson-convention C.
    """

    def __init__(self, q, C, convention="persson"):
        if convention not in CONVENTIONS:
            raise ValueError(f"convention = {convention!r} is invalid: must be one of "
                             f"{sorted(CONVENTIONS)} (Persson's C, or SurfaceTopography's (2π)² C)")
        q = as_float_array("q", q, "[1/m]")
        C = as_float_array("C", C, "[m^4]")
        for nm, arr in (("q", q), ("C", C)):
            if arr.ndim != 1:
                raise ValueError(f"{nm} has shape {arr.shape} (ndim = {arr.ndim}) is invalid: "
                                 f"must be a 1-D array of samples (a 2-D input is never "
                                 f"flattened)")
        if q.size < 2:
            raise ValueError(f"q has {q.size} samples: must have at least 2")
        if C.shape != q.shape:
            raise ValueError(f"C has shape {C.shape}: must match q's shape {q.shape}")
        check_positive("q", q, "[1/m]")
        check_positive("C", C, "[m^4]")
        d = np.diff(q)
        if np.any(d <= 0):
            i = int(np.argmax(d <= 0))
            kind = "duplicated" if d[i] == 0 else "unsorted"
            raise ValueError(f"q = {q[i + 1]!r} at index {i + 1} is invalid ({kind}): q must be "
                             f"strictly increasing")
        self.convention = convention
        self.q_samples = q
        self.C_samples = C * CONVENTIONS[convention]
        self.qb = q
        self.c = self.C_samples[:-1]
        self.e = np.log(self.C_samples[1:] / self.C_samples[:-1]) / np.log(q[1:] / q[:-1])
        # the log-log slope changes at every interior sample: quadratures must break there
        self.kinks = tuple(float(x) for x in q[1:-1])
        self._finish()

    def to_dict(self):
        return {"kind": "tabulated", "q": self.q_samples.tolist(), "C": self.C_samples.tolist(),
                "convention": "persson"}


def psd_from_dict(d: dict) -> PSD:
    """Rebuild a spectrum from :meth:`PSD.to_dict` output (plain data, never code)."""
    kind = d.get("kind")
    if kind == "self_affine":
        return SelfAffinePSD(d["h_rms"], d["hurst"], d["q0"], d["q1"], d.get("q_roll"))
    if kind == "tabulated":
        return TabulatedPSD(d["q"], d["C"], convention=d.get("convention", "persson"))
    if kind == "piecewise_power_law":
        return PiecewisePowerLawPSD(d["qb"], d["c"], d["e"], d.get("kinks", ()))
    raise ValueError(f"surface kind = {kind!r} is invalid: must be 'self_affine', 'tabulated' "
                     f"or 'piecewise_power_law'")
