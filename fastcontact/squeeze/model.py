"""The squeeze-out model of one (tables, theory): analytic tail above the table, trap
criterion, default start, and the cached time primitive.

Lorenz & Persson, Eur. Phys. J. E 32, 281 (2010), eqs. (3), (17)–(19), (23);
arXiv:1004.1037.
"""
from __future__ import annotations

import hashlib
import json
import math
import threading
import time as _clock
import weakref
from collections import namedtuple

import numpy as np

from .._core.vocab import DEFAULT_THEORY
from ..tables import Tables
from ..tables.tail import fit_tail
from . import _kernels as qk
from . import primitive as prim

__all__ = ["ModelPar", "SqueezeModel", "squeeze_model", "DEFAULT_P_START", "TAIL_EXTENT"]

#: default start: p_cont(u_start) = DEFAULT_P_START * p0 (the fluid carries 99.9 % of the load)
DEFAULT_P_START = 1e-3
#: extent of the analytic tail above the table top, in units of u0 (π drops by e^-40)
TAIL_EXTENT = 40.0

#: scalar model parameters (reduced units) passed to the kernels:
#: x_min, x_max  ln p̄ range of the tables; v_top, u0  ū/h_rms at the table top and the decay
#: length of eq. (3) there; c, d  the closed-form tail σ̄ = y³ - c y, y = v + d, above v_ext;
#: x_trap  ln π where σ̄ falls to sigma_trap (inf: never); v_ext  start of the closed-form
#: tail; x_perc  ln of the exact percolation pressure; v_trap  separation at x_trap;
#: lnp_start  ln DEFAULT_P_START; cn, g1..g5  the tail between v_top and v_ext,
#: σ̄ = y (y² - cn), y = v + d + g(1/v), g(x) = g1 x + ... + g5 x⁵ (see :func:`_tail_fit`)
ModelPar = namedtuple("ModelPar", "x_min x_max v_top u0 c x_trap v_ext x_perc v_trap "
                                  "lnp_start d cn g1 g2 g3 g4 g5")


def _ev(kernel, *args):
    xs = np.ascontiguousarray(args[-1], dtype=np.float64)
    out = np.empty(xs.size)
    kernel(*args[:-1], xs, out)
    return out


def _tail_fit(tab, x_min, samples=None, theory=None):
    """The table top and the analytic tail above it: (v_top, u0, tail) with tail a dict of
    the ModelPar fields c, d, cn, g1..g5, v_ext (v_ext None: v_top + TAIL_EXTENT u0).

    With the tables' tail samples (``info["tail"]``: direct ū and σ̄ below the lowest table
    pressure, up to ~340 h_rms), σ̄^(1/3) = v + d + g(1/v) is fitted to them and to the
    table top (:func:`fastcontact.tables.tail.fit_tail`); tables without samples get the old
    two-parameter tail σ̄ = y³ - c y, y = v + d, matched to the top in value and slope
    (leading order σ̄ = v³ is exact above the roughness; the effective medium's correction
    -2.2/v² is not of that form, so such tables are accurate to ~1e-5 in σ̄ above the top,
    not 1e-8)."""
    v_top = math.exp(_ev(qk.lnu_kernel, tab, np.array([x_min]))[0])
    # -dv/dln p at the top: the table's exact d ln ū/d ln p̄ at its first node (x_min), which
    # is also the interpolant's slope there (a forward difference with step 1e-4 was off by
    # 3e-11-9e-11 relative, which the tail's ln π = x_min - (v - v_top)/u0 multiplies by
    # (v - v_top)/u0: 7e-9-2.4e-8 at 380 h_rms; now <= 1.3e-9)
    u0 = -v_top * float(tab.dlnu[0])
    sig_top = float(_ev(qk.sigma_kernel, tab, np.array([x_min]))[0])
    # d ln σ̄/d ln p̄ at the top: likewise the first node's slope (was a one-sided difference)
    dlns_dx = float(tab.dlnsig[0])
    s1 = sig_top * dlns_dx / (-u0)                    # dσ̄/dv at the top
    y = v_top
    for _ in range(100):                              # 2y³ - s1 y + σ̄ = 0 near v_top
        f = 2 * y ** 3 - s1 * y + sig_top
        dy = f / (6 * y * y - s1)
        y -= dy
        if abs(dy) < 1e-15 * y:
            break
    d = y - v_top
    c = 3 * y * y - s1
    if not (abs(d) < 0.1 * v_top and abs(c) < 0.1 * y * y):   # fall back: value only
        d, c = 0.0, v_top ** 2 - sig_top / v_top
    tail = dict(c=c, d=d, cn=c, g1=0.0, g2=0.0, g3=0.0, g4=0.0, g5=0.0, v_ext=None)
    if samples is not None and theory in samples.get("sigma_bar", {}):
        tail = fit_tail(samples, theory, v_top, sig_top, v_top + TAIL_EXTENT * u0)
    return v_top, u0, tail


class SqueezeModel:
    """The per-(tables, theory) model: kernel records, tail, trap and the time primitive.

    Attributes
    ----------
    tab : tuple
        The tables' kernel record of ``theory``.
    mp : ModelPar
        Scalar model parameters (reduced units).
    h_rms : float
        Rms roughness [m].
    """

    def __init__(self, tables, theory, sigma_trap=None):
        t_start = _clock.perf_counter()
        self.tables = weakref.proxy(tables)
        self.theory = theory
        self.h_rms = float(tables.h_rms)
        tab = tables.kernel_data(theory)
        self.tab = tab
        p_lo, p_hi = tables.p_range
        x_min, x_max = math.log(p_lo), math.log(p_hi)
        self.sigma_trap = float(tables.info.get("sigma_floor", 1e-24) if sigma_trap is None
                                else sigma_trap)
        v_top, u0, tail = _tail_fit(tab, x_min, tables.info.get("tail"), theory)
        c, d = tail["c"], tail["d"]
        v_ext = v_top + TAIL_EXTENT * u0 if tail["v_ext"] is None else tail["v_ext"]
        perc = tables.info["percolation_p_over_E"][theory]
        x_perc = math.log(perc) if np.isfinite(perc) else math.inf
        x_trap = self._find_trap(tab, x_min, x_max, x_perc)
        mp = ModelPar(x_min, x_max, v_top, u0, c, x_trap, v_ext, x_perc,
                      math.nan, math.log(DEFAULT_P_START), d, tail["cn"], tail["g1"],
                      tail["g2"], tail["g3"], tail["g4"], tail["g5"])
        if np.isfinite(x_trap):
            v_trap = math.exp(_ev(qk.lnv_of_lnp_kernel, tab, mp, np.array([x_trap]))[0])
            mp = mp._replace(v_trap=v_trap)
        self.mp = mp
        self.x_min, self.x_max, self.x_trap, self.x_perc = x_min, x_max, x_trap, x_perc
        self.v_top, self.u0, self.c_tail, self.d_tail = v_top, u0, c, d
        self.tail = tail
        self._prim = None
        self._barus = None
        self._trap = None
        self._lock = threading.Lock()
        self.setup_seconds = _clock.perf_counter() - t_start

    def _find_trap(self, tab, x_min, x_max, x_perc):
        """ln π where σ̄ falls to sigma_trap (bisection on the tables' σ̄); inf if never."""
        if not np.isfinite(x_perc):
            return math.inf  # "average": σ̄ = v³ exactly, no percolation, nothing to floor
        hi = min(x_perc, x_max)
        if float(_ev(qk.sigma_kernel, tab, np.array([hi]))[0]) >= self.sigma_trap:
            return math.inf if x_perc > x_max else x_perc
        lo = x_min
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            if float(_ev(qk.sigma_kernel, tab, np.array([mid]))[0]) >= self.sigma_trap:
                lo = mid
            else:
                hi = mid
            if hi - lo < 1e-15:
                break
        return hi

    def primitive(self, cache_dir=None):
        """The time primitive of this model (built on first use, or read from ``cache_dir``)."""
        with self._lock:
            if self._prim is None:
                self._prim = prim.load_or_build(self, cache_dir)
            return self._prim

    def trap_primitive(self):
        """The trapped side's time primitive (:mod:`._trap_primitive`: cases above the trap
        pressure by interpolation; built on first use, ~10 ms on two cores with its error
        measured, or read from the primitive cache directory of the tables; its grid and
        measured error in ``trap_primitive_info``)."""
        with self._lock:
            if self._trap is None:
                from . import _trap_store
                self._trap, self.trap_primitive_info = _trap_store.load_or_build(self)
            return self._trap

    def barus_table(self):
        """(table, info) of the Barus correction beside the primitive (built on first use,
        5-20 ms, kept in memory; :mod:`._barus_primitive`)."""
        pr = self.primitive()
        with self._lock:
            if self._barus is None:
                from . import _barus_primitive
                self._barus = _barus_primitive.build(self, pr)
            return self._barus

    def p_of_v(self, v):
        """π_c(v) of the model (tables + analytic tail) at reduced separations v [-]."""
        return _ev(qk.p_of_v_kernel, self.tab, self.mp, v)

    def key(self):
        """Content key of this model (tables content, theory, trap floor, primitive version)."""
        t = self.tables
        raw = repr((t.surface.fingerprint(), tuple(t.theories), t.p_range,
                    int(t.info.get("nodes", -1)), sorted(t.options.items()), self.theory,
                    self.sigma_trap, prim.PRIMITIVE_VERSION, _digest(t),
                    json.dumps(t.info.get("tail"), sort_keys=True)))
        return hashlib.sha256(raw.encode()).hexdigest()[:32]


def _digest(tables):
    h = getattr(tables, "_squeeze_digest", None)
    if h is None:
        d = hashlib.sha256()
        for k in sorted(tables.data):
            d.update(k.encode())
            d.update(np.ascontiguousarray(tables.data[k]).tobytes())
        h = d.hexdigest()
        try:
            tables._squeeze_digest = h
        except AttributeError:
            pass
    return h


_MODELS: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()
_MODELS_LOCK = threading.Lock()


def _fingerprint(tables):
    return (tables.surface.fingerprint(), tuple(tables.theories), tables.p_range,
            int(tables.info.get("nodes", -1)), repr(sorted(tables.options.items())))


def squeeze_model(tables, theory=DEFAULT_THEORY, sigma_trap=None) -> SqueezeModel:
    """The cached :class:`SqueezeModel` of (tables, theory), built on first use.

    Parameters
    ----------
    tables : Tables
        Precomputed surface tables holding ``theory``.
    theory : str, default DEFAULT_THEORY ("critical_junction")
        Flow-conductivity theory.
    sigma_trap : float or None
        Reduced conductivity floor of the trap criterion [-] (default: the tables'
        ``info["sigma_floor"]``).
    """
    if not isinstance(tables, Tables):
        raise ValueError(f"tables = {tables!r} is invalid: must be a fastcontact Tables "
                         f"(fastcontact.precompute(...) or Tables.from_parquet(...))")
    tables._need(theory)
    fp = _fingerprint(tables)
    with _MODELS_LOCK:
        entry = _MODELS.get(tables)
        if entry is None or entry["fp"] != fp:
            entry = {"fp": fp}
            _MODELS[tables] = entry
        key = (theory, sigma_trap)
        if key not in entry:
            entry[key] = SqueezeModel(tables, theory, sigma_trap)
        return entry[key]
