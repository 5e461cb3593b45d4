"""Road-surface databases: many measured (or synthetic) power spectra, one per surface.

A database is either

* a **Parquet dataset** — a folder of ``*.parquet`` files (or one file) in long format with
  columns ``surface_id`` (string), ``q`` [1/m], ``C`` [m^4], one row per sample, rows of one
  surface contiguous or not (they are sorted by q on reading). The normalisation of C is
  given by the key-value metadata ``fastcontact.convention`` of each file or by a column
  ``convention``; ``"persson"`` or ``"surface_topography"`` ((2π)² × Persson). Extra columns
  (``h_rms``, ``hurst`` ... descriptors) are carried along but not needed; or
* a **folder of PSD files** (``*.csv`` / ``*.parquet`` readable by
  :func:`fastcontact.topography.read_psd`), one surface per file, ``surface_id`` = file stem;
  the convention comes from each Parquet file's metadata or from ``convention=``.

:func:`generate_road_database` writes a realistic synthetic database (asphalt-like spectra),
deterministic by seed.
"""
from __future__ import annotations

import hashlib
import json
import math
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from .._core.io import atomic_path
from .._core.vocab import CONVENTIONS
from .io import CONVENTION_KEY, read_psd
from .psd import TabulatedPSD

__all__ = ["generate_road_database", "open_road_database", "RoadDatabase", "CONVENTION_KEY",
           "synthetic_road_psd"]

DB_KEY = b"fastcontact.roaddb"
#: surfaces per Parquet part file written by generate_road_database
SURFACES_PER_PART = 250
#: samples per spectrum (log-spaced in q)
N_Q = 48
#: accepted rms slope range (asphalt: ξ ~ 1 over these bandwidths); draws outside are redrawn
MIN_SLOPE, MAX_SLOPE = 0.3, 4.0


def _atomic_write_table(table, path: Path):
    with atomic_path(path) as tmp:
        pq.write_table(table, tmp)
    return path


def synthetic_road_psd(rng, n_q=N_Q):
    """Parameters and (q, C_persson) samples of one asphalt-like spectrum.

    h_rms log-uniform in [0.1, 1] mm, Hurst H uniform in [0.7, 0.9], roll-off wavelength
    λ_r log-uniform in [1, 5] mm (q_roll = 2π/λ_r), q0 = q_roll / U(4, 10) (a flat
    plateau below the roll-off), q1 log-uniform in [1e5, 1e6] 1/m. Shape: the smooth roll-off
    form C ∝ (1 + (q/q_roll)²)^{-(1+H)} (flat below q_roll, C ∝ q^{-2(1+H)} above), times
    a mild smooth multiplicative "measurement" wiggle (±5 %, log-normal, correlated over
    ~0.3 decade), sampled on ``n_q`` log-spaced points from q0 to q1 and normalised so that
    the log-log interpolant has exactly the drawn h_rms. Roads have rms slopes of order 1;
    independent draws would reach ξ ≈ 20, so where ξ > MAX_SLOPE = 4 the cut-off q1 is
    lowered (not below 1e5 1/m) until ξ = 4, and draws that cannot be fixed that way or have
    ξ < MIN_SLOPE = 0.3 are redrawn.
    """

    def spectrum(q0, q1, n_q, q_roll, hurst, h_rms, smooth_noise):
        q = np.geomspace(q0, q1, n_q)
        shape = (1.0 + (q / q_roll) ** 2) ** (-(1.0 + hurst)) * np.exp(0.05 * smooth_noise)
        psd = TabulatedPSD(q, shape)
        return q, shape * (h_rms / psd.h_rms) ** 2, psd.rms_slope * h_rms / psd.h_rms

    while True:
        h_rms = 10.0 ** rng.uniform(-4.0, -3.0)
        hurst = rng.uniform(0.7, 0.9)
        lam_r = 10.0 ** rng.uniform(math.log10(1e-3), math.log10(5e-3))
        q_roll = 2.0 * math.pi / lam_r
        q0 = q_roll / rng.uniform(4.0, 10.0)
        q1 = 10.0 ** rng.uniform(5.0, 6.0)
        # smooth "measurement" wiggle: white noise smoothed over ~0.3 decade in log q
        x = np.linspace(0.0, 1.0, n_q)
        noise = rng.standard_normal(n_q)
        kern = np.exp(-0.5 * ((x[:, None] - x[None, :]) / (0.15 / 3.0)) ** 2)
        smooth = kern @ noise / np.sqrt((kern ** 2).sum(axis=1))
        q, C, slope = spectrum(q0, q1, n_q, q_roll, hurst, h_rms, smooth)
        if slope > MAX_SLOPE:
            # too steep for a road: lower q1 (not below 1e5) until the rms slope is MAX_SLOPE
            lo, hi = math.log(1e5), math.log(q1)
            if spectrum(q0, 1e5, n_q, q_roll, hurst, h_rms, smooth)[2] > MAX_SLOPE:
                continue
            for _ in range(40):
                mid = 0.5 * (lo + hi)
                if spectrum(q0, math.exp(mid), n_q, q_roll, hurst, h_rms, smooth)[2] > MAX_SLOPE:
                    hi = mid
                else:
                    lo = mid
            q1 = math.exp(lo)
            q, C, slope = spectrum(q0, q1, n_q, q_roll, hurst, h_rms, smooth)
        if slope >= MIN_SLOPE:
            break
    params = dict(h_rms=h_rms, hurst=hurst, q0=q0, q_roll=q_roll, q1=q1)
    return params, q, C


def generate_road_database(path, n_surfaces, seed, *, n_q=N_Q, surfaces_per_part=SURFACES_PER_PART,
                           convention="persson"):
    """Write a synthetic road database of ``n_surfaces`` asphalt-like spectra to folder ``path``.

    Deterministic: the same ``seed`` gives bit-identical files. Long format (``surface_id``,
    ``q``, ``C`` plus per-sample copies of the drawn descriptors ``h_rms``, ``hurst``, ``q0``,
    ``q_roll``, ``q1``), split into part files of ``surfaces_per_part`` surfaces each
    (``part-00000.parquet`` ...), written atomically. C is written in ``convention`` (recorded in
    the metadata). Surface ids are ``road-<seed>-<index:06d>``. Returns the folder path.

    See :func:`synthetic_road_psd` for the distribution of the spectra.
    """
    if isinstance(n_surfaces, bool) or not isinstance(n_surfaces, (int, np.integer)) or n_surfaces < 1:
        raise ValueError(f"n_surfaces = {n_surfaces!r} is invalid: must be an integer >= 1")
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f"seed = {seed!r} is invalid: must be an integer >= 0")
    if convention not in CONVENTIONS:
        raise ValueError(f"convention = {convention!r} is invalid: must be one of {sorted(CONVENTIONS)}")
    if isinstance(n_q, bool) or not isinstance(n_q, (int, np.integer)) or n_q < 4:
        raise ValueError(f"n_q = {n_q!r} is invalid: must be an integer >= 4")
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise ValueError(f"path = {str(path)!r} is invalid: exists and is not a folder")
    path.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(seed)
    n_parts = (int(n_surfaces) + surfaces_per_part - 1) // surfaces_per_part
    meta = {CONVENTION_KEY: convention.encode(),
            DB_KEY: json.dumps({"generator": "fastcontact.roaddb.generate_road_database",
                                "seed": int(seed), "n_surfaces": int(n_surfaces),
                                "n_q": int(n_q)}).encode(),
            b"fastcontact.units": b"q [1/m], C [m^4], h_rms [m], q0/q_roll/q1 [1/m]"}
    k = 0
    for part in range(n_parts):
        cols = {c: [] for c in ("surface_id", "q", "C", "h_rms", "hurst", "q0", "q_roll", "q1")}
        for _ in range(min(surfaces_per_part, int(n_surfaces) - k)):
            params, q, C = synthetic_road_psd(rng, n_q)
            sid = f"road-{int(seed)}-{k:06d}"
            cols["surface_id"].extend([sid] * q.size)
            cols["q"].append(q)
            cols["C"].append(C / CONVENTIONS[convention])
            for p in ("h_rms", "hurst", "q0", "q_roll", "q1"):
                cols[p].append(np.full(q.size, params[p]))
            k += 1
        arrays = {"surface_id": pa.array(cols["surface_id"], pa.string())}
        for c in ("q", "C", "h_rms", "hurst", "q0", "q_roll", "q1"):
            arrays[c] = pa.array(np.concatenate(cols[c]), pa.float64())
        table = pa.table(arrays).replace_schema_metadata(meta)
        _atomic_write_table(table, path / f"part-{part:05d}.parquet")
    return path


class RoadDatabase:
    """A road database opened for reading (see the module docstring).

    ``ids`` lists the surface ids (sorted); ``spectrum(id)`` returns (q, C_persson) arrays;
    ``psd(id)`` a :class:`~fastcontact.psd.TabulatedPSD`; ``fingerprint`` a hash of the content.
    """

    def __init__(self, path, convention=None):
        self.path = Path(path)
        self._spectra = {}
        self._files = {}
        if not self.path.exists():
            raise ValueError(f"database = {str(self.path)!r} is invalid: no such file or folder")
        if self.path.is_file():
            files = [self.path]
        else:
            files = sorted(p for p in self.path.rglob("*") if p.is_file()
                           and not p.name.startswith((".", "_"))
                           and p.name.lower().endswith((".parquet", ".pq", ".csv", ".csv.gz")))
        if not files:
            raise ValueError(f"database = {str(self.path)!r} is invalid: no .parquet or .csv files")
        long_files = []
        for f in files:
            if f.name.lower().endswith((".parquet", ".pq")) and "surface_id" in _parquet_columns(f):
                long_files.append(f)
            else:
                self._files[f.name.split(".")[0]] = f
        self.convention = convention
        for f in long_files:
            self._read_long(f, convention)
        if self._files and not long_files:
            pass
        dup = set(self._files) & set(self._spectra)
        if dup:
            raise ValueError(f"database = {str(self.path)!r} is invalid: surface ids "
                             f"{sorted(dup)[:3]} appear both as files and in the dataset")
        self.ids = sorted(set(self._spectra) | set(self._files))
        if not self.ids:
            raise ValueError(f"database = {str(self.path)!r} is invalid: no surfaces found")

    def _read_long(self, f, convention):
        try:
            table = pq.read_table(f)
        except Exception as exc:  # noqa: BLE001
            raise ValueError(f"database file {str(f)!r} cannot be read as Parquet ({exc})") from None
        for c in ("q", "C"):
            if c not in table.column_names:
                raise ValueError(f"database file {str(f)!r} is invalid: no column {c!r} "
                                 f"(columns: {table.column_names})")
        meta = (table.schema.metadata or {}).get(CONVENTION_KEY)
        stored = meta.decode() if meta is not None else None
        df = table.to_pandas()
        if "convention" in df.columns:
            convs = set(df["convention"].astype(str))
            if len(convs) != 1:
                raise ValueError(f"database file {str(f)!r}: mixed conventions {sorted(convs)}")
            col_conv = convs.pop()
            if stored is not None and stored != col_conv:
                raise ValueError(f"database file {str(f)!r}: convention column {col_conv!r} "
                                 f"contradicts metadata {stored!r}")
            stored = col_conv
        conv = stored if stored is not None else convention
        if conv is None:
            raise ValueError(f"convention is missing for {str(f)!r}: the file records none; "
                             f"pass --convention persson|surface_topography")
        if convention is not None and conv != convention:
            raise ValueError(f"convention = {convention!r} contradicts {str(f)!r}, which says {conv!r}")
        if conv not in CONVENTIONS:
            raise ValueError(f"database file {str(f)!r}: convention {conv!r} is not one of "
                             f"{sorted(CONVENTIONS)}")
        factor = CONVENTIONS[conv]
        df["surface_id"] = df["surface_id"].astype(str)
        for sid, g in df.groupby("surface_id", sort=True):
            if sid in self._spectra:
                raise ValueError(f"database: surface_id {sid!r} appears in more than one file")
            g = g.sort_values("q", kind="stable")
            self._spectra[sid] = (np.ascontiguousarray(g["q"].to_numpy(np.float64)),
                                  np.ascontiguousarray(g["C"].to_numpy(np.float64) * factor))

    def __len__(self):
        return len(self.ids)

    def spectrum(self, sid):
        """(q [1/m], C [m^4], Persson convention) of surface ``sid``."""
        if sid in self._spectra:
            return self._spectra[sid]
        if sid in self._files:
            f = self._files[sid]
            conv = self.convention
            if conv is None and f.name.lower().endswith((".parquet", ".pq")):
                m = (pq.read_schema(f).metadata or {}).get(CONVENTION_KEY)
                conv = m.decode() if m is not None else None
            if conv is None:
                raise ValueError(f"convention is missing for {str(f)!r}: pass --convention "
                                 f"persson|surface_topography")
            psd = read_psd(f, conv)
            self._spectra[sid] = (psd.q_samples, psd.C_samples)
            return self._spectra[sid]
        raise KeyError(f"surface_id {sid!r} is not in the database")

    def psd(self, sid):
        q, C = self.spectrum(sid)
        return TabulatedPSD(q, C, convention="persson")

    @property
    def fingerprint(self):
        h = hashlib.sha256()
        for sid in self.ids:
            q, C = self.spectrum(sid)
            h.update(sid.encode())
            h.update(np.ascontiguousarray(q).tobytes())
            h.update(np.ascontiguousarray(C).tobytes())
        return h.hexdigest()


def _parquet_columns(f):
    try:
        return pq.read_schema(f).names
    except Exception:  # noqa: BLE001
        return []


def open_road_database(path, convention=None) -> RoadDatabase:
    """Open a road database (a Parquet dataset or a folder of PSD files)."""
    return RoadDatabase(path, convention)
