"""A cache of surface tables keyed by content.

The key of a cached table is the SHA-256 of the surface fingerprint (its canonical PSD
definition), the theories, the table options, the table schema version and the fastcontact
version. A cached file is used only if it reads back intact (checksums verified by
:meth:`Tables.from_parquet`) *and* its own metadata match the request; otherwise it is rebuilt.
Files are written atomically.
"""
from __future__ import annotations

import dataclasses
import hashlib
import json
import math
import os
import time
from pathlib import Path

from .. import __version__
from .._core.vocab import METADATA_KEY, THEORIES
from . import SCHEMA_VERSION, Tables, precompute

__all__ = ["TableCache", "TableRecord", "table_cache_dir", "table_key", "build_tables",
           "obtain_tables", "read_table_metadata", "surface_mismatch"]


def table_cache_dir(explicit=None) -> Path:
    """The table cache folder.

    ``explicit``, else ``$FASTCONTACT_CACHE_DIR``, else
    ``platformdirs.user_cache_dir("fastcontact")/tables`` (``~/.cache/fastcontact/tables`` on
    Linux).
    """
    if explicit:
        return Path(explicit).expanduser()
    env = os.environ.get("FASTCONTACT_CACHE_DIR")
    if env:
        return Path(env).expanduser()
    try:
        from platformdirs import user_cache_dir   # core dependency; lazy: only when needed
        base = Path(user_cache_dir("fastcontact"))
    except ImportError:
        xdg = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
        base = Path(xdg) / "fastcontact"
    return base / "tables"


def _canonical_theories(theories) -> tuple:
    ths = set(theories)
    return tuple(t for t in THEORIES if t in ths)


def table_key(psd, theories, options) -> str:
    """Cache key: surface fingerprint + theories + table options + schema + version."""
    blob = json.dumps({"surface": psd.fingerprint(), "theories": list(_canonical_theories(theories)),
                       "options": {k: float(v) for k, v in sorted(options.items())},
                       "schema": SCHEMA_VERSION, "version": __version__},
                      sort_keys=True).encode()
    return hashlib.sha256(blob).hexdigest()


def build_tables(psd, theories, options):
    """``precompute`` with the study's theories and options; returns ``(Tables, note)``.

    If the adaptive refinement cannot resolve ū(p) as strictly decreasing (seen for some
    tabulated spectra whose quadrature noise exceeds the refinement tolerance), the build is
    retried on the base grid without refinement and ``note`` says so; the interpolation errors
    actually achieved are in ``Tables.info["interpolation_error"]``.
    """
    theories = _canonical_theories(theories)
    try:
        return precompute(psd, theories=theories, **options), None
    except ValueError as exc:
        if "strictly decreasing" not in str(exc):
            raise
        t = precompute(psd, theories=theories, refine=False, **options)
        err = t.info.get("interpolation_error", {})
        worst = max(err.values()) if err else float("nan")
        return t, (f"adaptive refinement failed ({exc}); built on the base grid without "
                   f"refinement, worst interpolation error {worst:.2g}")


def read_table_metadata(path) -> dict:
    """The fastcontact metadata of a tables file (the Parquet schema only, no data read)."""
    import pyarrow.parquet as pq
    try:
        schema = pq.read_schema(path)
    except Exception as exc:  # noqa: BLE001 - pyarrow raises several types
        raise ValueError(f"cannot read {str(path)!r} as Parquet ({type(exc).__name__})") from None
    raw = (schema.metadata or {}).get(METADATA_KEY)
    if raw is None:
        raise ValueError(f"{str(path)!r} is not a fastcontact tables file (no metadata)")
    try:
        return json.loads(raw)
    except ValueError:
        raise ValueError(f"{str(path)!r} has corrupted fastcontact metadata") from None


def _describe_surface(d: dict) -> str:
    kind = d.get("kind", "?")
    if kind == "self_affine":
        return ("self-affine h_rms = {h_rms:.6g} m, H = {hurst:.6g}, q0 = {q0:.6g} 1/m, "
                "q1 = {q1:.6g} 1/m, q_roll = {qr}").format(
                    qr="none" if d.get("q_roll") is None else f"{d['q_roll']:.6g} 1/m", **d)
    if kind == "tabulated":
        q = d.get("q", [])
        return (f"tabulated spectrum, {len(q)} samples, q = {q[0]:.6g}..{q[-1]:.6g} 1/m"
                if q else "tabulated spectrum")
    return f"{kind} spectrum"


def surface_mismatch(meta: dict, psd) -> str | None:
    """``None`` if the table's surface is ``psd``, else a message showing both surfaces."""
    if meta.get("surface_hash") == psd.fingerprint():
        return None
    return (f"the table was built for a different surface: table: "
            f"{_describe_surface(meta.get('surface', {}))}; scene: "
            f"{_describe_surface(psd.to_dict())}")


@dataclasses.dataclass(frozen=True)
class TableRecord:
    """How one surface's tables were obtained (for the build record and provenance).

    ``action`` is ``"loaded"`` (a table file), ``"reused"`` (cache hit) or ``"built"``;
    ``seconds`` [s] is the time taken, ``build_seconds`` [s] the original build time.
    Supports ``record["key"]`` like the dict it replaces.
    """

    surface: str
    action: str
    path: str | None
    theories: list
    options: dict
    surface_hash: str
    columns_sha256: str
    nodes: int | None
    seconds: float
    build_seconds: float | None
    note: str | None

    def __getitem__(self, key):
        return getattr(self, key)

    def get(self, key, default=None):
        return getattr(self, key, default)

    def to_dict(self) -> dict:
        return dataclasses.asdict(self)


class TableCache:
    """Surface tables kept in ``folder`` (None: no cache, tables are always built).

    Parameters
    ----------
    folder : path-like or None
        Cache folder; see :func:`table_cache_dir` for the default location.
    """

    def __init__(self, folder=None):
        self.folder = None if folder is None else Path(folder)

    def path(self, psd, theories, options) -> Path | None:
        """The cache file of (psd, theories, options), or None without a cache folder."""
        if self.folder is None:
            return None
        key = table_key(psd, theories, options)
        return self.folder / f"{psd.fingerprint()[:16]}-{key[:16]}.parquet"

    def _lookup(self, path, psd, theories, options):
        """(Tables or None, note) of a cache file that must match the request exactly."""
        if path is None or not path.is_file():
            return None, None
        try:
            T = Tables.from_parquet(path)
        except ValueError as exc:
            return None, f"cache file unusable ({exc}): rebuilt"
        ok = (T.surface.fingerprint() == psd.fingerprint() and tuple(T.theories) == theories
              and all(math.isclose(T.options.get(k, math.nan), v) for k, v in options.items()))
        return (T, None) if ok else (None, "cache file did not match: rebuilt")

    def get(self, psd, theories, options):
        """Tables of ``psd`` with ``theories`` and table ``options``: cached or built.

        Returns
        -------
        tables : Tables
        action : str
            ``"reused"`` or ``"built"``.
        path : Path or None
            The cache file (written if built).
        note : str or None
            Why a cache file was not used, or that a build fell back to the base grid.
        """
        theories = _canonical_theories(theories)
        path = self.path(psd, theories, options)
        T, note = self._lookup(path, psd, theories, options)
        if T is not None:
            return T, "reused", path, None
        T, bnote = build_tables(psd, theories, options)
        if path is not None:
            T.to_parquet(path)
        return T, "built", path, "; ".join(x for x in (note, bnote) if x) or None


def obtain_tables(spec, theories, options, cache_dir=None):
    """Tables for one scene surface: load its table file, reuse the cache or build.

    Parameters
    ----------
    spec : fastcontact.studies.scene.SurfaceSpec
        The surface (``spec.source == "table"``: a table file is read and checked).
    theories : sequence of str
    options : dict
        Table options (``gamma``, ``a_perc``, ``alpha_cj``).
    cache_dir : path-like or None
        Cache folder (None: build without caching).

    Returns
    -------
    (Tables, TableRecord)
    """
    t0 = time.perf_counter()
    theories = _canonical_theories(theories)
    note = None
    if spec.source == "table":
        T = Tables.from_parquet(spec.path)
        action, path = "loaded", spec.path
    else:
        T, action, path, note = TableCache(cache_dir).get(spec.psd(), theories, options)
    meta = T.metadata()
    rec = TableRecord(surface=spec.name, action=action, path=str(path) if path else None,
                      theories=list(T.theories), options=T.options,
                      surface_hash=meta["surface_hash"], columns_sha256=meta["columns_sha256"],
                      nodes=T.info.get("nodes"), seconds=round(time.perf_counter() - t0, 4),
                      build_seconds=T.info.get("build_seconds"), note=note)
    return T, rec
