"""The :class:`Tables` of one surface: evaluation through :mod:`fastcontact.kernels.lookup`,
Parquet I/O and provenance metadata with a SHA-256 digest over every byte that changes a result."""
from __future__ import annotations

import hashlib
import json
import math
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from .. import __version__
from .._core.io import atomic_path
from .._core.validate import check_positive
from .._core.vocab import METADATA_KEY, THEORIES, reference_list
from ..flow.conductivity import check_theory
from ..kernels.locate import Grid, build_bucket_map
from ..kernels.lookup import TableKernel, eval_p, eval_sigma, eval_u
from ..surface.psd import PSD, psd_from_dict
from ..kernels.readonly import readonly_fields

__all__ = ["Tables", "TableRangeError", "SCHEMA_VERSION", "UNITS", "REFERENCES", "column_unit"]

#: Parquet format version; 3: the digest ``metadata_sha256`` covers all metadata and columns
SCHEMA_VERSION = 3
#: literature cited in every table file (citations with DOIs)
REFERENCES = reference_list(["lorenz_persson_2010_squeeze", "persson_2001", "yang_persson_2008",
                             "lorenz_persson_2010_seals", "almqvist_2011", "patir_cheng_1978"])

#: unit of every column (all dimensionless; the string says what the number is)
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
for _d in ("x", "y"):   # anisotropic tables (precompute(anisotropy=γ_T)): the emt directions
    UNITS[f"sigma_emt_{_d}"] = f"1 (12 eta sigma_{_d}{_d} / h_rms^3)"
    UNITS[f"dlnsigma_emt_{_d}"] = f"1 (d ln sigma_bar_{_d}{_d} / d ln p_bar)"
    UNITS[f"d2lnsigma_emt_{_d}"] = f"1 (d2 ln sigma_bar_{_d}{_d} / d ln p_bar2)"
    UNITS[f"phi_emt_{_d}"] = f"1 (pressure flow factor, {_d})"
    UNITS[f"percolated_emt_{_d}"] = "bool"


class TableRangeError(ValueError):
    """A value outside the tabulated range was requested (the message names it, in SI)."""


def column_unit(name: str) -> str:
    """Unit string of column ``name``; new columns register theirs in :data:`UNITS`."""
    try:
        return UNITS[name]
    except KeyError:
        raise ValueError(f"column = {name!r} is invalid: it has no unit; add it to "
                         f"fastcontact.tables.store.UNITS before writing") from None


def _column_digest(data: dict) -> str:
    """SHA-256 over the names, dtypes and bytes of all columns (sorted by name)."""
    h = hashlib.sha256()
    for k in sorted(data):
        a = np.ascontiguousarray(data[k])
        h.update(k.encode())
        h.update(str(a.dtype).encode())
        h.update(a.tobytes())
    return h.hexdigest()


def _canonical(meta: dict) -> bytes:
    """Canonical JSON of a metadata block without its own digest."""
    body = {k: v for k, v in meta.items() if k != "metadata_sha256"}
    return json.dumps(body, sort_keys=True, separators=(",", ":"), allow_nan=True).encode()


def _metadata_digest(meta: dict) -> str:
    """SHA-256 of the canonical metadata (which holds the column digest) and that digest."""
    h = hashlib.sha256(_canonical(meta))
    h.update(str(meta.get("columns_sha256")).encode())
    return h.hexdigest()


def _lnsig_and_open(sig):
    """(ln σ̄ with -inf where σ̄ = 0, number of leading nodes with σ̄ > 0)."""
    open_ = sig > 0
    with np.errstate(divide="ignore"):
        lnsig = np.ascontiguousarray(np.where(open_, np.log(np.where(open_, sig, 1.0)), -np.inf))
    n_open = int(np.argmin(open_)) if not np.all(open_) else int(sig.size)
    return lnsig, n_open


class Tables:
    """Reduced-unit contact and conductivity tables of one surface (see :mod:`fastcontact.tables`).

    Build with :func:`~fastcontact.tables.precompute`; save with :meth:`to_parquet`, load with
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

    def percolation_area(self, theory):
        """Area fraction A(ζ1)/A0 [-] at which ``theory``'s σ_eff vanishes (inf: never).

        ``options["a_perc"]`` (critical junction), ``options.get("emt_threshold", 0.5)``
        (effective medium; set by a calibration), inf ("average"). The one place engines
        read the percolation threshold from.
        """
        self._need(theory)
        if theory == "critical_junction":
            return float(self.options.get("a_perc", 0.5))
        if theory == "emt":
            a = float(self.options.get("emt_threshold", 0.5))
            d = self.options.get("direction")
            if d is not None and self.options.get("anisotropy_form") == "fixed":
                g = float(self.options["anisotropy"]) ** (1 if d == "x" else -1)
                a = g * a / (1.0 - a + g * a)      # a directional view: odds scaled by γ_T^±1
            return a
        return math.inf

    def percolation_pressure(self, theory, E_star=1.0):
        """Contact pressure [Pa] at which ``theory``'s σ_eff vanishes (inf: never).

        That is where A(ζ1)/A0 reaches the tables' threshold: ``options["a_perc"]`` for the
        critical junction, ``options.get("emt_threshold", 0.5)`` for the effective medium
        (both set by a calibration, see :func:`~fastcontact.tables.precompute`).

        Parameters
        ----------
        theory : {"average", "critical_junction", "emt"}
            A theory these tables hold.
        E_star : float or array_like
            Effective modulus [Pa], > 0 (default 1: the reduced pressure p̄_c [-]).
        """
        self._need(theory)
        E_star = check_positive("E_star", E_star, "[Pa]")
        return (self.info["percolation_p_over_E"][theory] * E_star)[()]

    def _need(self, theory):
        check_theory(theory)
        if theory not in self.theories:
            raise ValueError(f"theory = {theory!r} is invalid for these tables: they hold "
                             f"{list(self.theories)} (rebuild with theories=... to add it)")

    def check_surface(self, psd, what="the requested surface"):
        """Raise ValueError, showing both descriptions, unless ``psd`` is this table's surface."""
        if psd.fingerprint() != self.surface.fingerprint():
            raise ValueError(f"tables surface {self.surface!r} does not match {what} {psd!r} "
                             f"(fingerprints {self.surface.fingerprint()[:12]} vs "
                             f"{psd.fingerprint()[:12]}): use tables built for that surface")

    # ------------------------------------------------------------------ kernels
    def kernel_data(self, theory) -> TableKernel:
        """The flat :class:`~fastcontact.kernels.lookup.TableKernel` of ``theory`` (built once).

        Pass it to :func:`~fastcontact.kernels.lookup.k_lnu_of_lnp`, ``k_lnp_of_lnu``,
        ``k_sigma_of_lnp``, ``k_state_of_lnu``. It is a tuple with a fixed field order, so
        positional reads (``tab[13]`` is ``tab.d2lnu``) keep working.
        """
        self._need(theory)
        if theory not in self._kernel_cache:
            lnsig, n_open = _lnsig_and_open(self.data[f"sigma_{theory}"])
            p_perc = self.info["percolation_p_over_E"][theory]
            lnp_perc = math.log(p_perc) if np.isfinite(p_perc) else math.inf
            self._kernel_cache[theory] = readonly_fields(TableKernel(
                self._ln_p, self._lnu, self._dlnu, lnsig,
                np.ascontiguousarray(self.data[f"dlnsigma_{theory}"], dtype=np.float64),
                float(lnp_perc), n_open, *self._bp, *self._bu, self._d2lnu,
                np.ascontiguousarray(self.data[f"d2lnsigma_{theory}"], dtype=np.float64)))
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
                f"{name} = {v!r} Pa is invalid: outside the table, which covers {name}/E* in "
                f"[{lo:.6g}, {hi:.6g}] (that is [{lo * e:.6g}, {hi * e:.6g}] Pa at E* = {e:g} Pa)")
        return np.clip(pb, lo, hi)

    def _ubar(self, u):
        u = check_positive("u", u, "[m]")
        ub = np.asarray(u / self.h_rms, dtype=np.float64)
        lo, hi = float(np.exp(self._lnu[-1])), float(np.exp(self._lnu[0]))
        bad = (ub < lo * (1 - 1e-13)) | (ub > hi * (1 + 1e-13))
        if np.any(bad):
            v = float(np.asarray(u * np.ones_like(ub))[bad].ravel()[0])
            raise TableRangeError(
                f"u = {v!r} m is invalid: outside the table, which covers u in "
                f"[{lo * self.h_rms:.6g}, {hi * self.h_rms:.6g}] m (u/h_rms in [{lo:.6g}, {hi:.6g}])")
        return ub

    # ------------------------------------------------------------------ evaluation
    def mean_separation(self, p, E_star):
        """Mean separation ū [m] at contact pressure p [Pa] for modulus E_star [Pa] (A4).

        Raises :class:`TableRangeError` outside the tabulated p/E* range.
        """
        pb = self._pbar("p", p, E_star)
        out = np.empty(pb.size)
        eval_u(self.kernel_data(self.theories[0]), np.ascontiguousarray(np.log(pb).ravel()), out)
        return (out.reshape(pb.shape) * self.h_rms)[()]

    def contact_pressure(self, u, E_star):
        """Contact pressure p_cont [Pa] at mean separation u [m] (inverse of ū(p)), E_star [Pa]."""
        ub = self._ubar(u)
        E_star = check_positive("E_star", E_star, "[Pa]")
        lnq = np.ascontiguousarray(np.clip(np.log(ub), self._lnu[-1], self._lnu[0]).ravel())
        out = np.empty(lnq.size)
        eval_p(self.kernel_data(self.theories[0]), lnq, out)
        return (out.reshape(ub.shape) * E_star)[()]

    def _direction(self, direction, theory):
        """The tables to read for ``direction`` (see :meth:`conductivity`)."""
        from ..flow.anisotropy import tables_for_direction
        return tables_for_direction(self, direction, theory)

    def sigma_bar(self, p, E_star, theory, direction=None):
        """Reduced conductivity σ̄ = 12ησ_eff/h_rms³ [-] at contact pressure p [Pa] (eq. 23);
        ``direction`` as in :meth:`conductivity`."""
        if direction is not None:
            return self._direction(direction, theory).sigma_bar(p, E_star, theory)
        tab = self.kernel_data(theory)
        pb = self._pbar("p", p, E_star)
        out = np.empty(pb.size)
        eval_sigma(tab, np.ascontiguousarray(np.log(pb).ravel()), out)
        return out.reshape(pb.shape)[()]

    def conductivity(self, p, E_star, eta, theory, direction=None):
        """σ_eff [m³/(Pa·s)] at contact pressure p [Pa], viscosity eta [Pa·s]; 0 where percolated.

        Parameters
        ----------
        p : array_like
            Contact pressure [Pa].
        E_star : float or array_like
            Effective modulus [Pa].
        eta : float or array_like
            Viscosity [Pa·s].
        theory : {"average", "critical_junction", "emt"}
            A theory these tables hold.
        direction : {None, "x", "y"}
            Flow direction for tables built with ``precompute(..., anisotropy=γ_T)``: σ_xx
            (along the long correlation length) or σ_yy of the anisotropic effective medium
            ("emt"; "average" carries no direction; "critical_junction" raises ValueError).
            None: the isotropic columns. On isotropic tables (γ_T = 1) every direction gives
            the result of None, bit for bit (σ_xx = σ_yy = σ for isotropic roughness).
        """
        eta = check_positive("eta", eta, "[Pa·s]")
        return self.sigma_bar(p, E_star, theory, direction) * self.h_rms ** 3 / (12.0 * eta)

    def flow_factor(self, p, E_star, theory, direction=None):
        """Pressure flow factor φ_p = 12ησ_eff/ū³ [-] at contact pressure p [Pa] (``direction``
        as in :meth:`conductivity`)."""
        return self.sigma_bar(p, E_star, theory, direction) / (
            self.mean_separation(p, E_star) / self.h_rms) ** 3

    def percolated(self, p, E_star, theory):
        """True where the contact has percolated for ``theory`` (σ_eff = 0, fluid trapped)."""
        self._need(theory)
        pb = self._pbar("p", p, E_star)
        return pb >= self.info["percolation_p_over_E"][theory]

    # ------------------------------------------------------------------ Parquet
    def metadata(self) -> dict:
        """The provenance written to Parquet (JSON-serialisable), with its SHA-256 digests.

        ``columns_sha256`` covers the column bytes; ``metadata_sha256`` covers the canonical
        JSON of everything else (info, options, theories, grids, surface, ...) and the columns.
        """
        meta = {
            "schema_version": SCHEMA_VERSION,
            "fastcontact_version": __version__,
            "surface": self.surface.to_dict(),
            "surface_hash": self.surface.fingerprint(),
            "h_rms_m": self.h_rms,
            "theories": list(self.theories),
            "options": self.options,
            "grids": {"p_over_E": self.grid.to_list(), "zeta": self.zeta_grid.to_list()},
            "info": self.info,
            "units": {k: column_unit(k) for k in self.data},
            "columns_sha256": _column_digest(self.data),
            "references": REFERENCES,
        }
        meta = json.loads(json.dumps(meta))  # normalise to what a reader sees
        meta["metadata_sha256"] = _metadata_digest(meta)
        return meta

    def to_parquet(self, path):
        """Write the tables to ``path`` atomically (temporary file, then rename); returns the path."""
        path = Path(path)
        fields, arrays = [], []
        for k, v in self.data.items():
            arr = pa.array(v)
            fields.append(pa.field(k, arr.type, metadata={"unit": column_unit(k)}))
            arrays.append(arr)
        meta = {METADATA_KEY: json.dumps(self.metadata(), sort_keys=True).encode()}
        table = pa.Table.from_arrays(arrays, schema=pa.schema(fields, metadata=meta))
        with atomic_path(path) as tmp:
            pq.write_table(table, tmp, write_page_checksum=True)
        return path

    @classmethod
    def from_parquet(cls, path):
        """Read tables written by :meth:`to_parquet`, refusing damaged, altered or old files."""
        path = Path(path)
        if not path.is_file():
            raise FileNotFoundError(f"tables file {str(path)!r} does not exist")
        try:
            table = pq.read_table(path, page_checksum_verification=True)
        except Exception as exc:  # noqa: BLE001 - pyarrow raises several types
            raise ValueError(f"tables file {str(path)!r} is truncated or corrupted and cannot be "
                             f"read as Parquet ({type(exc).__name__}: {exc})") from None
        meta = _read_meta(path, table)
        if _metadata_digest(meta) != meta.get("metadata_sha256"):
            raise ValueError(f"tables file {str(path)!r}: its metadata (options, info, theories, "
                             f"grids, surface, ...) do not match the recorded SHA-256 hash "
                             f"metadata_sha256: the file was altered after it was written; "
                             f"rebuild it with `fastcontact tables build`")
        surface = psd_from_dict(meta["surface"])
        if surface.fingerprint() != meta.get("surface_hash"):
            raise ValueError(f"tables file {str(path)!r}: the surface hash does not match its "
                             f"surface definition (file altered or mismatched)")
        data = {name: np.ascontiguousarray(table.column(name).to_numpy())
                for name in table.column_names}
        if _column_digest(data) != meta.get("columns_sha256"):
            raise ValueError(f"tables file {str(path)!r}: column data do not match the recorded "
                             f"checksum (file corrupted or altered)")
        return cls(surface, meta["theories"], meta["options"], Grid(*meta["grids"]["p_over_E"]),
                   Grid(*meta["grids"]["zeta"]), data, meta["info"])

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
            elif a.shape != b.shape or not np.allclose(a, b, rtol=rtol, atol=0.0, equal_nan=True):
                return False
        return True


def _read_meta(path, table) -> dict:
    """The fastcontact metadata block of a Parquet table, schema version checked."""
    raw = (table.schema.metadata or {}).get(METADATA_KEY)
    if raw is None:
        raise ValueError(f"tables file {str(path)!r} has no fastcontact metadata: it was not "
                         f"written by fastcontact Tables.to_parquet")
    try:
        meta = json.loads(raw)
    except ValueError:
        raise ValueError(f"tables file {str(path)!r} has corrupted fastcontact metadata") from None
    if not isinstance(meta, dict):
        raise ValueError(f"tables file {str(path)!r} has corrupted fastcontact metadata")
    ver = meta.get("schema_version")
    if ver != SCHEMA_VERSION:
        raise ValueError(f"tables file {str(path)!r} has schema_version = {ver!r}: this "
                         f"fastcontact {__version__} reads schema_version {SCHEMA_VERSION} only "
                         f"(rebuild it with `fastcontact tables build`)")
    return meta
