"""Precomputed contact and flow tables of one surface, in reduced units, and their Parquet form.

One table serves every E* and η: columns are functions of the reduced contact pressure
``p̄ = p/E*`` on a log grid, with separations in units of h_rms and conductivities as
``σ̄ = 12 η σ_eff / h_rms³`` (eq. 23). The grid reaches from ū ≈ 30 h_rms (the
asymptotic regime) to A(ζ1)/A0 = 0.999 (full contact).

Columns (``Tables.data``), all dimensionless:

=====================  ================================================================
p_over_E               p̄ = p_cont/E* (grid nodes)
u_over_h               ū/h_rms                                                 (A4)
dlnu_dlnp              d ln ū / d ln p̄ (exact, from the same quadrature)
d2lnu_dlnp2            d² ln ū / d(ln p̄)² (exact)
area_fraction          A(ζ1)/A0                                                (A1)
sigma_<theory>         σ̄ for each requested theory (0 where percolated)        (23)
dlnsigma_<theory>      d ln σ̄ / d ln p̄ (critical junction: central differences of the exact
                       quadrature; effective medium: local quartic through the nodes)
d2lnsigma_<theory>     d² ln σ̄ / d(ln p̄)², likewise
phi_<theory>           pressure flow factor φ_p = σ̄ (h_rms/ū)³               (Sec. 4)
percolated_<theory>    True where the contact percolates (σ_eff = 0, fluid trapped)
zeta_c, u1c_over_h     critical-junction magnification and u1(ζc)/h_rms      (A3)
zeta, G_over_Estar2    G(ζ)/E*² on the log ζ grid (same number of rows)          (A2)
=====================  ================================================================

Interpolation: quintic Hermite in ln p̄ of ln ū (and of the inverse ln p̄(ln ū)) with exact
first and second derivatives; likewise quintic Hermite of ln σ̄; in the one
grid interval that contains a theory's percolation pressure, σ̄^(1/3) is interpolated
linearly in ln p̄ to zero at the exact percolation pressure (closed form from A(ζ1)).
Outside the grid nothing is extrapolated: Python methods raise, kernels return a flag.
"""
from __future__ import annotations

import hashlib
import json
import math
import time
from pathlib import Path

import numpy as np
from numba import njit

from .. import __version__
from .._core.validate import check_positive, check_range
from ..flow.conductivity import EMT_TOL, THEORIES, check_theory, sigma_bar
from ..contact import _check_gamma, _check_psd, _separation, asymptote, percolation_pressure
from .._core.io import atomic_path
from ..kernels.locate import (Grid, build_bucket_map, locate_asc, locate_desc,
                    quintic_interval)
from ..surface.psd import PSD, psd_from_dict

__all__ = ["Tables", "precompute", "DEFAULT_POINTS_PER_DECADE", "SCHEMA_VERSION"]

SCHEMA_VERSION = 2
METADATA_KEY = b"fastcontact"
#: default grid density in p̄ (chosen from bench/bench_tables.py, see bench/RESULTS.md)
DEFAULT_POINTS_PER_DECADE = 8
#: the table reaches from ū = U_TOP h_rms ...
U_TOP = 32.0
#: ... to A(ζ1)/A0 = AREA_TOP
AREA_TOP = 0.999

REFERENCES = [
    "B. Lorenz and B.N.J. Persson, Fluid squeeze-out between solids with rough surfaces, "
    "Eur. Phys. J. E 32, 281 (2010)",
    "B.N.J. Persson, Theory of rubber friction and contact mechanics, J. Chem. Phys. 115, 3840 (2001)",
    "C. Yang and B.N.J. Persson, Contact mechanics: contact area and interfacial separation "
    "from small contact to full contact, J. Phys.: Condens. Matter 20, 215214 (2008)",
    "B. Lorenz and B.N.J. Persson, Leak rate of seals: effective-medium theory and comparison "
    "with experiment, Eur. Phys. J. E 31, 159 (2010)",
    "A. Almqvist, C. Campañá, N. Prodanov, B.N.J. Persson, Interfacial separation between "
    "elastic solids with randomly rough surfaces, J. Mech. Phys. Solids 59, 2355 (2011)",
    "N. Patir and H.S. Cheng, An average flow model for determining effects of "
    "three-dimensional roughness on partial hydrodynamic lubrication, J. Lubr. Technol. 100, 12 (1978)",
]

UNITS = {
    "p_over_E": "1 (p_cont / E*)", "u_over_h": "1 (mean separation / h_rms)",
    "dlnu_dlnp": "1", "d2lnu_dlnp2": "1", "area_fraction": "1 (A(zeta1)/A0)", "zeta_c": "1 (magnification)",
    "u1c_over_h": "1 (u1(zeta_c) / h_rms)", "zeta": "1 (magnification)",
    "G_over_Estar2": "1 (G(zeta) / E*^2)",
}
for _t in THEORIES:
    UNITS[f"sigma_{_t}"] = "1 (12 eta sigma_eff / h_rms^3)"
    UNITS[f"dlnsigma_{_t}"] = "1 (d ln sigma_bar / d ln p_bar)"
    UNITS[f"d2lnsigma_{_t}"] = "1 (d2 ln sigma_bar / d ln p_bar2)"
    UNITS[f"phi_{_t}"] = "1 (pressure flow factor)"
    UNITS[f"percolated_{_t}"] = "bool"


class TableRangeError(ValueError):
    """A value outside the tabulated range was requested."""


# =========================================================================== kernels
# A theory's kernel tuple ``tab`` (Tables.kernel_data) is
#   (lnp, lnu, dlnu, lnsig, dlnsig, lnp_perc, n_open, bp_lo, bp_dz, bp_idx, bu_lo, bu_dz, bu_idx,
#    d2lnu, d2lnsig)
# lnp: ln p̄ at the nodes (increasing); lnu: ln(ū/h_rms) (decreasing); dlnu = d ln ū/d ln p̄,
# d2lnu = its derivative (exact, from the quadrature: ū(p̄) and its inverse are quintic Hermite);
# lnsig, dlnsig: ln σ̄ and d ln σ̄/d ln p̄ (-inf / 0 where σ̄ = 0); lnp_perc: ln of the exact
# percolation pressure (inf: none); n_open: number of leading nodes with σ̄ > 0;
# bp_*, bu_*: O(1) bucket locators over ln p̄ and -ln ū.
@njit(cache=True)
def k_lnu_of_lnp(tab, lnp_q):
    """ln(ū/h_rms) at ln p̄ (quintic Hermite); NaN outside the table."""
    lnp, lnu, dlnu, d2 = tab[0], tab[1], tab[2], tab[13]
    i = locate_asc(lnp_q, lnp, tab[7], tab[8], tab[9])
    if i < 0:
        return math.nan
    return quintic_interval(lnp_q, lnp[i], lnp[i + 1], lnu[i], lnu[i + 1], dlnu[i], dlnu[i + 1],
                            d2[i], d2[i + 1])


@njit(cache=True)
def k_lnp_of_lnu(tab, lnu_q):
    """ln p̄ at ln(ū/h_rms) (inverse; quintic Hermite in ln ū); NaN outside the table."""
    lnp, lnu, dlnu, d2 = tab[0], tab[1], tab[2], tab[13]
    i = locate_desc(lnu_q, lnu, tab[10], tab[11], tab[12])
    if i < 0:
        return math.nan
    a0 = dlnu[i]
    a1 = dlnu[i + 1]
    return quintic_interval(lnu_q, lnu[i], lnu[i + 1], lnp[i], lnp[i + 1], 1.0 / a0, 1.0 / a1,
                            -d2[i] / a0 ** 3, -d2[i + 1] / a1 ** 3)


@njit(cache=True)
def k_sigma_of_lnp(tab, lnp_q):
    """σ̄ = 12ησ_eff/h_rms³ at ln p̄; exactly 0 at and beyond percolation; NaN outside.

    Quintic Hermite of ln σ̄ between open nodes; between the last open node and the exact
    percolation pressure σ̄^(1/3) falls linearly in ln p̄ to 0 (σ̄ < 1e-30 there).
    """
    lnp, lnsig, dlnsig, lnp_perc, n_open = tab[0], tab[3], tab[4], tab[5], tab[6]
    i = locate_asc(lnp_q, lnp, tab[7], tab[8], tab[9])
    if i < 0:
        return math.nan
    if lnp_q >= lnp_perc:
        return 0.0
    if i + 1 < n_open:
        d2 = tab[14]
        return math.exp(quintic_interval(lnp_q, lnp[i], lnp[i + 1], lnsig[i], lnsig[i + 1],
                                         dlnsig[i], dlnsig[i + 1], d2[i], d2[i + 1]))
    j = n_open - 1
    if j < 0 or lnp_perc == math.inf:
        return 0.0
    cr = math.exp(lnsig[j] / 3.0) * (lnp_perc - lnp_q) / (lnp_perc - lnp[j])
    return cr * cr * cr


@njit(cache=True)
def k_state_of_lnu(tab, lnu_q):
    """(p̄, σ̄, flag) at ln(ū/h_rms): flag 0 inside the table, 1 outside (values NaN)."""
    lnp = k_lnp_of_lnu(tab, lnu_q)
    if lnp != lnp:
        return math.nan, math.nan, 1
    return math.exp(lnp), k_sigma_of_lnp(tab, lnp), 0


@njit(cache=True)
def _eval_u_kernel(tab, lnp, out):
    for i in range(lnp.size):
        out[i] = math.exp(k_lnu_of_lnp(tab, lnp[i]))


@njit(cache=True)
def _eval_p_kernel(tab, lnuq, out):
    for i in range(lnuq.size):
        out[i] = math.exp(k_lnp_of_lnu(tab, lnuq[i]))


@njit(cache=True)
def _eval_sigma_kernel(tab, lnp, out):
    for i in range(lnp.size):
        out[i] = k_sigma_of_lnp(tab, lnp[i])


# =========================================================================== helpers
def _column_digest(data: dict) -> str:
    h = hashlib.sha256()
    for k in sorted(data):
        a = np.ascontiguousarray(data[k])
        h.update(k.encode())
        h.update(str(a.dtype).encode())
        h.update(a.tobytes())
    return h.hexdigest()


def _theory_options(theories, gamma, a_perc, alpha_cj, emt_tol, emt_almqvist):
    if isinstance(theories, str):
        theories = (theories,)
    theories = tuple(dict.fromkeys(check_theory(t) for t in theories))
    if not theories:
        raise ValueError("theories = () is invalid: request at least one of "
                         f"{list(THEORIES)}")
    return theories, {
        "gamma": _check_gamma(gamma),
        "a_perc": float(check_range("a_perc", a_perc, 0.0, 1.0, "[-]", lo_open=True, hi_open=True)),
        "alpha_cj": float(check_positive("alpha_cj", alpha_cj, "[-]")),
        "emt_tol": float(check_range("emt_tol", emt_tol, 1e-13, 1e-2, "[-]")),
        "emt_almqvist": bool(emt_almqvist),
    }


# =========================================================================== Tables
class Tables:
    """Reduced-unit contact and conductivity tables of one surface (see module docstring).

    Build with :func:`precompute`; save with :meth:`to_parquet`, load with
    :meth:`from_parquet`. Evaluate with :meth:`mean_separation`, :meth:`contact_pressure`,
    :meth:`conductivity`, :meth:`flow_factor`; pass :meth:`kernel_data` to numba kernels.
    """

    def __init__(self, surface: PSD, theories, options: dict, grid: Grid, zeta_grid: Grid,
                 data: dict, info: dict):
        self.surface = surface
        self.theories = tuple(theories)
        self.options = dict(options)
        self.grid = Grid(*grid)
        self.zeta_grid = Grid(*zeta_grid)
        self.data = data
        self.info = dict(info)
        self.h_rms = surface.h_rms
        self._ln_p = np.ascontiguousarray(np.log(data["p_over_E"]))
        self._lnu = np.ascontiguousarray(np.log(data["u_over_h"]))
        self._dlnu = np.ascontiguousarray(data["dlnu_dlnp"])
        self._d2lnu = np.ascontiguousarray(data["d2lnu_dlnp2"])
        self._bp = build_bucket_map(self._ln_p, ascending=True)
        self._bu = build_bucket_map(self._lnu)
        self._kernel_cache = {}

    # ------------------------------------------------------------------ introspection
    def __repr__(self):
        g = self.grid
        return (f"Tables({self.surface!r}, theories={self.theories}, p/E* = 1e{g.log10_min:.2f}"
                f"..1e{g.log10_max:.2f} ({g.n} nodes), options={self.options})")

    @property
    def p_range(self):
        """(p̄_min, p̄_max): the tabulated range of p_cont/E* [-]."""
        return float(self.data["p_over_E"][0]), float(self.data["p_over_E"][-1])

    @property
    def u_range(self):
        """(ū_min/h_rms, ū_max/h_rms): the tabulated range of separations [-]."""
        return float(self.data["u_over_h"][-1]), float(self.data["u_over_h"][0])

    def percolation_pressure(self, theory, E_star=1.0):
        """Contact pressure [Pa] at which ``theory``'s σ_eff vanishes (inf: never)."""
        check_theory(theory)
        self._need(theory)
        return self.info["percolation_p_over_E"][theory] * E_star

    def _need(self, theory):
        check_theory(theory)
        if theory not in self.theories:
            raise ValueError(f"theory = {theory!r} is invalid for these tables: they hold "
                             f"{list(self.theories)} (rebuild with theories=... to add it)")

    # ------------------------------------------------------------------ kernels
    def kernel_data(self, theory):
        """Tuple of contiguous arrays and scalars for the numba kernels of ``theory``.

        Pass it to :func:`k_lnu_of_lnp`, :func:`k_lnp_of_lnu`, :func:`k_sigma_of_lnp`,
        :func:`k_state_of_lnu` (layout in the comment above those kernels). Built once.
        """
        self._need(theory)
        if theory not in self._kernel_cache:
            sig = self.data[f"sigma_{theory}"]
            open_ = sig > 0
            with np.errstate(divide="ignore"):
                lnsig = np.ascontiguousarray(np.where(open_, np.log(np.where(open_, sig, 1.0)),
                                                      -np.inf))
            n_open = int(np.argmin(open_)) if not np.all(open_) else int(sig.size)
            p_perc = self.info["percolation_p_over_E"][theory]
            lnp_perc = math.log(p_perc) if np.isfinite(p_perc) else math.inf
            self._kernel_cache[theory] = (
                self._ln_p, self._lnu, self._dlnu, lnsig,
                np.ascontiguousarray(self.data[f"dlnsigma_{theory}"], dtype=np.float64),
                float(lnp_perc), n_open, *self._bp, *self._bu, self._d2lnu,
                np.ascontiguousarray(self.data[f"d2lnsigma_{theory}"], dtype=np.float64))
        return self._kernel_cache[theory]

    # ------------------------------------------------------------------ range checks
    def _pbar(self, name, p, E_star):
        p = check_positive(name, p, "[Pa]")
        E_star = check_positive("E_star", E_star, "[Pa]")
        pb = np.asarray(p / E_star, dtype=np.float64)
        lo, hi = self.data["p_over_E"][0], self.data["p_over_E"][-1]
        bad = (pb < lo * (1 - 1e-13)) | (pb > hi * (1 + 1e-13))
        if np.any(bad):
            v = float(np.asarray(p * np.ones_like(pb))[bad].ravel()[0])
            e = float(np.asarray(E_star * np.ones_like(pb))[bad].ravel()[0])
            raise TableRangeError(
                f"{name} = {v!r} is invalid: outside the table, which covers {name}/E* in "
                f"[{lo:.6g}, {hi:.6g}] (that is [{lo * e:.6g}, {hi * e:.6g}] Pa at E* = {e:g} Pa)")
        return np.clip(pb, lo, hi)

    # ------------------------------------------------------------------ evaluation
    def mean_separation(self, p, E_star):
        """ū [m] at contact pressure p [Pa] for modulus E_star [Pa] (interpolated A4)."""
        pb = self._pbar("p", p, E_star)
        out = np.empty(pb.size)
        _eval_u_kernel(self.kernel_data(self.theories[0]), np.ascontiguousarray(np.log(pb).ravel()), out)
        return (out.reshape(pb.shape) * self.h_rms)[()]

    def contact_pressure(self, u, E_star):
        """Contact pressure p_cont [Pa] at mean separation u [m] (inverse of ū(p))."""
        u = check_positive("u", u, "[m]")
        E_star = check_positive("E_star", E_star, "[Pa]")
        ub = np.asarray(u / self.h_rms, dtype=np.float64)
        lo, hi = float(np.exp(self._lnu[-1])), float(np.exp(self._lnu[0]))
        bad = (ub < lo * (1 - 1e-13)) | (ub > hi * (1 + 1e-13))
        if np.any(bad):
            v = float(np.asarray(u * np.ones_like(ub))[bad].ravel()[0])
            raise TableRangeError(
                f"u = {v!r} is invalid: outside the table, which covers u in "
                f"[{lo * self.h_rms:.6g}, {hi * self.h_rms:.6g}] m (u/h_rms in [{lo:.6g}, {hi:.6g}])")
        lnq = np.ascontiguousarray(np.clip(np.log(ub), self._lnu[-1], self._lnu[0]).ravel())
        out = np.empty(lnq.size)
        _eval_p_kernel(self.kernel_data(self.theories[0]), lnq, out)
        return (out.reshape(ub.shape) * E_star)[()]

    def sigma_bar(self, p, E_star, theory):
        """Reduced conductivity σ̄ = 12ησ_eff/h_rms³ [-] at contact pressure p [Pa]."""
        tab = self.kernel_data(theory)
        pb = self._pbar("p", p, E_star)
        out = np.empty(pb.size)
        _eval_sigma_kernel(tab, np.ascontiguousarray(np.log(pb).ravel()), out)
        return out.reshape(pb.shape)[()]

    def conductivity(self, p, E_star, eta, theory):
        """σ_eff [m³/(Pa·s)] at contact pressure p [Pa]; exactly 0 where percolated."""
        eta = check_positive("eta", eta, "[Pa·s]")
        return self.sigma_bar(p, E_star, theory) * self.h_rms ** 3 / (12.0 * eta)

    def flow_factor(self, p, E_star, theory):
        """Pressure flow factor φ_p = 12ησ_eff/ū³ [-] at contact pressure p [Pa]."""
        return self.sigma_bar(p, E_star, theory) / (self.mean_separation(p, E_star) / self.h_rms) ** 3

    def percolated(self, p, E_star, theory):
        """True where the contact has percolated for ``theory`` (σ_eff = 0, fluid trapped)."""
        self._need(theory)
        pb = self._pbar("p", p, E_star)
        return pb >= self.info["percolation_p_over_E"][theory]

    # ------------------------------------------------------------------ Parquet
    def metadata(self) -> dict:
        """The provenance written to Parquet (JSON-serialisable)."""
        return {
            "schema_version": SCHEMA_VERSION,
            "fastcontact_version": __version__,
            "surface": self.surface.to_dict(),
            "surface_hash": self.surface.fingerprint(),
            "h_rms_m": self.h_rms,
            "theories": list(self.theories),
            "options": self.options,
            "grids": {"p_over_E": self.grid.to_list(), "zeta": self.zeta_grid.to_list()},
            "info": self.info,
            "units": {k: UNITS[k] for k in self.data},
            "columns_sha256": _column_digest(self.data),
            "references": REFERENCES,
        }

    def to_parquet(self, path):
        """Write the tables to ``path`` atomically (temporary file, then rename)."""
        import pyarrow as pa
        import pyarrow.parquet as pq

        path = Path(path)
        fields, arrays = [], []
        for k, v in self.data.items():
            arr = pa.array(v)
            fields.append(pa.field(k, arr.type, metadata={"unit": UNITS[k]}))
            arrays.append(arr)
        meta = {METADATA_KEY: json.dumps(self.metadata(), sort_keys=True).encode()}
        table = pa.Table.from_arrays(arrays, schema=pa.schema(fields, metadata=meta))
        with atomic_path(path) as tmp:
            pq.write_table(table, tmp, write_page_checksum=True)
        return path

    @classmethod
    def from_parquet(cls, path):
        """Read tables written by :meth:`to_parquet`, refusing damaged or mismatched files."""
        import pyarrow.parquet as pq

        path = Path(path)
        if not path.is_file():
            raise FileNotFoundError(f"tables file {str(path)!r} does not exist")
        try:
            table = pq.read_table(path, page_checksum_verification=True)
        except Exception as exc:  # noqa: BLE001 - pyarrow raises several types
            raise ValueError(f"tables file {str(path)!r} is truncated or corrupted and cannot be "
                             f"read as Parquet ({type(exc).__name__}: {exc})") from None
        raw = (table.schema.metadata or {}).get(METADATA_KEY)
        if raw is None:
            raise ValueError(f"tables file {str(path)!r} has no fastcontact metadata: it was not "
                             f"written by fastcontact Tables.to_parquet")
        try:
            meta = json.loads(raw)
        except ValueError:
            raise ValueError(f"tables file {str(path)!r} has corrupted fastcontact metadata") from None
        ver = meta.get("schema_version")
        if ver != SCHEMA_VERSION:
            raise ValueError(f"tables file {str(path)!r} has schema_version = {ver!r}: this "
                             f"fastcontact {__version__} reads schema_version {SCHEMA_VERSION} only "
                             f"(rebuild it with `fastcontact tables build`)")
        surface = psd_from_dict(meta["surface"])
        if surface.fingerprint() != meta.get("surface_hash"):
            raise ValueError(f"tables file {str(path)!r}: the surface hash does not match its "
                             f"surface definition (file altered or mismatched)")
        data = {name: table.column(name).to_numpy() for name in table.column_names}
        data = {k: np.ascontiguousarray(v) for k, v in data.items()}
        if _column_digest(data) != meta.get("columns_sha256"):
            raise ValueError(f"tables file {str(path)!r}: column data do not match the recorded "
                             f"checksum (file corrupted or altered)")
        info = meta["info"]
        return cls(surface, meta["theories"], meta["options"], Grid(*meta["grids"]["p_over_E"]),
                   Grid(*meta["grids"]["zeta"]), data, info)

    def equals(self, other, rtol=0.0) -> bool:
        """Same surface, options and columns (bit-for-bit when rtol = 0)."""
        if self.surface.fingerprint() != other.surface.fingerprint():
            return False
        if self.theories != other.theories or self.options != other.options:
            return False
        if set(self.data) != set(other.data):
            return False
        for k in self.data:
            a, b = self.data[k], other.data[k]
            if rtol == 0.0:
                if a.dtype != b.dtype or not np.array_equal(a, b, equal_nan=True):
                    return False
            elif not np.allclose(a, b, rtol=rtol, atol=0.0, equal_nan=True):
                return False
        return True


# =========================================================================== precompute
#: relative interpolation tolerances the adaptive refinement enforces at interval midpoints
TOLERANCE = {"u": 5e-9, "p_of_u": 5e-9, "slope": 5e-8, "sigma": 2e-7}
#: σ̄ below this is "at percolation" for the refinement (not resolved further; time scales
#: there exceed 1e20 τ-units)
SIGMA_FLOOR = 1e-24
BOUNDARY_FACTOR = 1e3
MAX_NODES = 6000
MIN_DLNP = 1e-6


def default_grid(surface: PSD, gamma=1.0, points_per_decade=DEFAULT_POINTS_PER_DECADE) -> Grid:
    """Base p̄ grid from ū ≈ 32 h_rms (asymptote) to A(ζ1)/A0 = 0.999, snapped to 1/ppd decades."""
    u0, beta = asymptote(surface, gamma)
    p_lo = beta * math.exp(-U_TOP * surface.h_rms / u0)
    p_hi = float(percolation_pressure(surface, 1.0, AREA_TOP))
    ppd = int(points_per_decade)
    lo = math.floor(math.log10(p_lo) * ppd) / ppd
    hi = math.ceil(math.log10(p_hi) * ppd) / ppd
    return Grid(lo, hi, int(round((hi - lo) * ppd)) + 1)


def _exact(psd, pbar, theories, sig_opts):
    """Exact columns at reduced pressures pbar (direct quadrature)."""
    pbar = np.ascontiguousarray(pbar, dtype=np.float64)
    u, du, d2u = _separation(psd, pbar, 1.0, 1.0, sig_opts["gamma"], second=True)
    h = psd.h_rms
    out = {"u": u / h, "dlnu": du / u, "d2lnu": d2u / u - (du / u) ** 2}
    for th in theories:
        sb, perc, extra = sigma_bar(psd, pbar, th, **sig_opts)
        out[f"sigma_{th}"] = sb
        out[f"percolated_{th}"] = perc
        if th == "average":
            out[f"dlnsigma_{th}"] = 3.0 * out["dlnu"]
            out[f"d2lnsigma_{th}"] = 3.0 * out["d2lnu"]
        elif th == "critical_junction":
            eps = 1e-4
            up, _, _ = sigma_bar(psd, pbar * math.exp(eps), th, **sig_opts)
            um, _, _ = sigma_bar(psd, pbar * math.exp(-eps), th, **sig_opts)
            with np.errstate(divide="ignore", invalid="ignore"):
                d = (np.log(up) - np.log(um)) / (2 * eps)
                d2 = (np.log(up) - 2 * np.log(sb) + np.log(um)) / eps ** 2
            out[f"dlnsigma_{th}"] = np.where(np.isfinite(d) & (sb > 0), d, 0.0)
            out[f"d2lnsigma_{th}"] = np.where(np.isfinite(d2) & (sb > 0), d2, 0.0)
            out["zeta_c"] = extra["zeta_c"]
            out["u1c_over_h"] = extra["u1c"]
    return out


def _node_derivative(x, y, ok):
    """(dy/dx, d²y/dx²) at the open nodes from the degree-4 polynomial through the 5 nearest."""
    d = np.zeros_like(y)
    d2 = np.zeros_like(y)
    idx = np.flatnonzero(ok)
    m = idx.size
    if m < 3:
        return d, d2
    w = min(5, m)
    k = np.arange(m)
    lo = np.clip(k - w // 2, 0, m - w)
    sten = idx[lo[:, None] + np.arange(w)[None, :]]            # (m, w) node indices
    dx = x[sten] - x[idx][:, None]                             # local abscissae
    V = dx[:, :, None] ** np.arange(w)[None, None, :]          # Vandermonde (m, w, w)
    coef = np.linalg.solve(V, y[sten][:, :, None])[:, :, 0]
    d[idx] = coef[:, 1]
    d2[idx] = 2.0 * coef[:, 2]
    return d, d2


def _quintic_np(x, x0, x1, y0, y1, d0, d1, s0, s1, deriv=False):
    h = x1 - x0
    t = (x - x0) / h
    if deriv:
        return ((-30 * t ** 2 + 60 * t ** 3 - 30 * t ** 4) * y0 / h
                + (1 - 18 * t ** 2 + 32 * t ** 3 - 15 * t ** 4) * d0
                + 0.5 * (2 * t - 9 * t ** 2 + 12 * t ** 3 - 5 * t ** 4) * h * s0
                + (30 * t ** 2 - 60 * t ** 3 + 30 * t ** 4) * y1 / h
                + (-12 * t ** 2 + 28 * t ** 3 - 15 * t ** 4) * d1
                + 0.5 * (3 * t ** 2 - 8 * t ** 3 + 5 * t ** 4) * h * s1)
    return ((1 - 10 * t ** 3 + 15 * t ** 4 - 6 * t ** 5) * y0
            + (t - 6 * t ** 3 + 8 * t ** 4 - 3 * t ** 5) * h * d0
            + 0.5 * (t ** 2 - 3 * t ** 3 + 3 * t ** 4 - t ** 5) * h * h * s0
            + (10 * t ** 3 - 15 * t ** 4 + 6 * t ** 5) * y1
            + (-4 * t ** 3 + 7 * t ** 4 - 3 * t ** 5) * h * d1
            + 0.5 * (t ** 3 - 2 * t ** 4 + t ** 5) * h * h * s1)


def _interval_errors(lnp, cols, mids, theories):
    """Relative midpoint errors of each column's interpolant, per interval (inf: overflow)."""
    with np.errstate(over="ignore", invalid="ignore"):
        return _interval_errors_raw(lnp, cols, mids, theories)


def _interval_errors_raw(lnp, cols, mids, theories):
    x0, x1 = lnp[:-1], lnp[1:]
    xm = 0.5 * (x0 + x1)
    lnu = np.log(cols["u"])
    du = cols["dlnu"]
    d2 = cols["d2lnu"]
    args = (x0, x1, lnu[:-1], lnu[1:], du[:-1], du[1:], d2[:-1], d2[1:])
    est = _quintic_np(xm, *args)
    err = {"u": np.abs(np.expm1(est - np.log(mids["u"])))}
    slope = _quintic_np(xm, *args, deriv=True)
    err["slope"] = np.abs(slope / mids["dlnu"] - 1.0)
    lnum = np.log(mids["u"])
    est_p = _quintic_np(lnum, lnu[:-1], lnu[1:], x0, x1, 1 / du[:-1], 1 / du[1:],
                        -d2[:-1] / du[:-1] ** 3, -d2[1:] / du[1:] ** 3)
    err["p_of_u"] = np.abs(np.expm1(est_p - xm))
    for th in theories:
        s = cols[f"sigma_{th}"]
        sm = mids[f"sigma_{th}"]
        ok = (s[:-1] > SIGMA_FLOOR) & (s[1:] > SIGMA_FLOOR) & (sm > SIGMA_FLOOR)
        e = np.zeros(xm.size)
        if np.any(ok):
            ds = cols[f"dlnsigma_{th}"]
            d2s = cols[f"d2lnsigma_{th}"]
            est_s = _quintic_np(xm[ok], x0[ok], x1[ok], np.log(s[:-1][ok]), np.log(s[1:][ok]),
                                ds[:-1][ok], ds[1:][ok], d2s[:-1][ok], d2s[1:][ok])
            e[ok] = np.abs(np.expm1(est_s - np.log(sm[ok])))
        err[f"sigma_{th}"] = e
    return err


def precompute(psd, theories=("average", "critical_junction", "emt"), gamma=1.0, a_perc=0.5,
               alpha_cj=1.0, grid=None, *, emt_tol=EMT_TOL, emt_almqvist=False,
               points_per_decade=None, tolerance=None, refine=True):
    """Tabulate ū, A, u1(ζc), σ̄ and φ_p of a surface on a log grid of p̄ = p/E* (SPEC §2–3).

    The base grid (uniform in ln p̄) is refined adaptively: every interval whose Hermite
    interpolant misses the exact quadrature at its midpoint by more than ``tolerance``
    (relative; ū, p_cont(ū), the slope d ln ū/d ln p̄ that sets squeeze-out rates near
    equilibrium, and each σ̄ above SIGMA_FLOOR) is split, until all pass.
    The midpoint errors of the final grid are recorded in ``info["interpolation_error"]``.

    Parameters
    ----------
    psd : PSD            the roughness spectrum (Persson convention)
    theories : sequence  any of "average", "critical_junction", "emt"; only these are computed
    gamma : float        Yang–Persson factor (1 = the paper's A4)
    a_perc : float       critical-junction percolation threshold A(ζc)/A0 (0.5; 0.42 option)
    alpha_cj : float     critical-junction factor on u1(ζc)
    grid : Grid or (log10_min, log10_max, n), optional   base p̄ grid (default: default_grid)
    emt_tol : float      relative accuracy of the adaptive effective-medium integral
    emt_almqvist : bool  Almqvist-broadened separation distribution in the effective medium
    points_per_decade : int, optional  density of the default base grid
    tolerance : dict, optional  overrides of TOLERANCE ("u", "p_of_u", "slope", "sigma")
    refine : bool        False: keep the base grid (errors are still measured and recorded)
    """
    t_start = time.perf_counter()
    _check_psd(psd)
    theories, options = _theory_options(theories, gamma, a_perc, alpha_cj, emt_tol, emt_almqvist)
    gamma = options["gamma"]
    if grid is None:
        grid = default_grid(psd, gamma, points_per_decade or DEFAULT_POINTS_PER_DECADE)
    else:
        grid = Grid(float(grid[0]), float(grid[1]), int(grid[2]))
        if not (grid.n >= 5 and grid.log10_max > grid.log10_min):
            raise ValueError(f"grid = {tuple(grid)!r} is invalid: must be (log10_min, log10_max, n) "
                             f"with log10_max > log10_min and n >= 5")
    tol = dict(TOLERANCE)
    tol.update(tolerance or {})
    sig_opts = dict(gamma=gamma, a_perc=options["a_perc"], alpha_cj=options["alpha_cj"],
                    tol=options["emt_tol"], almqvist=options["emt_almqvist"])
    h = psd.h_rms
    lnp = grid.ln_nodes()
    cols = _exact(psd, np.exp(lnp), theories, sig_opts)
    mid_cache = {}
    rounds = 0
    while True:
        rounds += 1
        if "emt" in theories:
            s = cols["sigma_emt"]
            ok = s > SIGMA_FLOOR
            with np.errstate(divide="ignore"):
                cols["dlnsigma_emt"], cols["d2lnsigma_emt"] = _node_derivative(
                    lnp, np.where(ok, np.log(np.where(ok, s, 1)), 0), ok)
        xm = 0.5 * (lnp[:-1] + lnp[1:])
        need = np.array([x not in mid_cache for x in xm])
        if np.any(need):
            new = _exact(psd, np.exp(xm[need]), theories, sig_opts)
            for k, x in enumerate(xm[need]):
                mid_cache[x] = {c: v[k] for c, v in new.items()}
        mids = {c: np.array([mid_cache[x][c] for x in xm]) for c in cols
                if c not in ("dlnsigma_emt", "d2lnsigma_emt")}
        if not np.all(np.diff(np.log(np.concatenate(([cols["u"][0]], mids["u"])))) < 0) \
                or not np.all(np.diff(cols["u"]) < 0):
            raise ValueError(f"grid = {tuple(grid)!r} is invalid for this surface: ū(p) is not "
                             f"resolved as strictly decreasing")
        errs = _interval_errors(lnp, cols, mids, theories)
        bad = np.zeros(xm.size, dtype=bool)
        for c, e in errs.items():
            bad |= e > tol["sigma" if c.startswith("sigma") else c]
        # intervals straddling the σ̄ floor (the super-exponential collapse of u1(ζc) before
        # percolation) are bisected until their open end is within BOUNDARY_FACTOR of it
        for th in theories:
            sg = cols[f"sigma_{th}"]
            above = sg > SIGMA_FLOOR
            straddle = above[:-1] != above[1:]
            open_end = np.maximum(sg[:-1], sg[1:])
            bad |= straddle & (open_end > BOUNDARY_FACTOR * SIGMA_FLOOR)
        bad &= (lnp[1:] - lnp[:-1]) > 2 * MIN_DLNP
        if not refine or not np.any(bad) or lnp.size + bad.sum() > MAX_NODES:
            break
        # split: the midpoints become nodes (their exact values are already known)
        add = xm[bad]
        order = np.argsort(np.concatenate((lnp, add)), kind="stable")
        lnp = np.concatenate((lnp, add))[order]
        for c in cols:
            extra = mids[c][bad] if c in mids else np.zeros(int(bad.sum()))
            cols[c] = np.concatenate((cols[c], extra))[order]
    pbar = np.exp(lnp)
    data = {"p_over_E": pbar, "u_over_h": cols["u"], "dlnu_dlnp": cols["dlnu"],
            "d2lnu_dlnp2": cols["d2lnu"]}
    G1 = 0.25 * math.pi * psd.cum3[-1]
    from scipy.special import erf
    data["area_fraction"] = erf(pbar / (2.0 * math.sqrt(G1)))
    perc_p = {}
    for th in theories:
        data[f"sigma_{th}"] = cols[f"sigma_{th}"]
        data[f"dlnsigma_{th}"] = np.where(cols[f"sigma_{th}"] > 0, cols[f"dlnsigma_{th}"], 0.0)
        data[f"d2lnsigma_{th}"] = np.where(cols[f"sigma_{th}"] > 0, cols[f"d2lnsigma_{th}"], 0.0)
        data[f"phi_{th}"] = cols[f"sigma_{th}"] / cols["u"] ** 3
        data[f"percolated_{th}"] = cols[f"percolated_{th}"].astype(bool)
        if th == "critical_junction":
            data["zeta_c"] = cols["zeta_c"]
            data["u1c_over_h"] = cols["u1c_over_h"]
        perc_p[th] = (math.inf if th == "average" else
                      float(percolation_pressure(psd, 1.0, options["a_perc"] if th == "critical_junction" else 0.5)))
    zg = Grid(0.0, math.log10(psd.zeta1), pbar.size)
    zeta = zg.nodes()
    zeta[-1] = psd.zeta1
    data["zeta"] = zeta
    data["G_over_Estar2"] = 0.25 * math.pi * np.asarray(psd.moment(3.0, psd.q0, zeta * psd.q0))
    data = {k: np.ascontiguousarray(v) for k, v in data.items()}
    u0, beta = asymptote(psd, gamma)
    info = {"asymptote_u0_over_h": u0 / h, "asymptote_beta": beta,
            "percolation_p_over_E": perc_p,
            "interpolation_error": {c: float(e.max()) for c, e in errs.items()},
            "tolerance": tol, "sigma_floor": SIGMA_FLOOR, "nodes": int(pbar.size),
            "refinement_rounds": rounds, "exact_evaluations": int(grid.n + len(mid_cache)),
            "build_seconds": time.perf_counter() - t_start}
    return Tables(psd, theories, options, grid, zg, data, info)
