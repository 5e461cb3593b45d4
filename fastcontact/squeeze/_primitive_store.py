"""The time primitive on disk: Parquet files keyed by the model's content key.

Part of :mod:`fastcontact.squeeze.primitive`. A file holds one primitive (rows = x0 nodes,
the z-node columns ln T, d ln T/dz, d² ln T/dz² as fixed-size lists) with its grid, version,
key and measured interpolation error in the metadata; it is written atomically and read back
with page checksums, and a damaged or foreign file raises ValueError (then rebuilt).
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from .._core.io import atomic_path
from .._core.vocab import METADATA_KEY
from ..kernels.readonly import readonly_fields
from ._primitive_build import build
from ._primitive_eval import Primitive, _index_map, lagrange_denominators

__all__ = ["load_or_build", "write", "read", "set_primitive_cache", "primitive_path",
           "PRIMITIVE_VERSION"]

#: format and model version of the stored primitives (files of another version are rebuilt);
#: 3: the tail's decay length u0 from the table's exact slope at its top (2026-11-26)
#: 4: z grid spacing 0.2 instead of 0.25; no slope_below column (the slope below the grid
#: is e^ln_S) (2026-11-27)
#: 5: profile at 0.001 in ln v; rows up to 1e-4 below the trap pressure and the kink, ending
#: at the tables' last verified node (2026-12-07)
PRIMITIVE_VERSION = 5
_CACHE_ATTR = "_squeeze_primitive_dir"


def set_primitive_cache(tables, directory):
    """Keep the time primitives of ``tables`` in ``directory`` (Parquet, keyed by content):
    later calls on equal tables, in this or another process, read them instead of building."""
    setattr(tables, _CACHE_ATTR, None if directory is None else Path(directory))


def primitive_path(directory, model) -> Path:
    """File of ``model``'s primitive in ``directory``."""
    return Path(directory) / f"squeeze_primitive_{model.theory}_{model.key()}.parquet"


def load_or_build(model, cache_dir=None):
    """The primitive of ``model``: read from the cache directory if present, else built (and
    written there when a directory is configured)."""
    if cache_dir is None:
        cache_dir = getattr(model.tables, _CACHE_ATTR, None)
    if cache_dir is not None:
        path = primitive_path(cache_dir, model)
        if path.is_file():
            try:
                pr, info = read(path, expect_key=model.key())
                model.primitive_info = info
                return pr
            except ValueError:
                pass  # damaged or stale: rebuild and overwrite
    pr, info = build(model, check=cache_dir is not None)
    model.primitive_info = info
    if cache_dir is not None:
        write(primitive_path(cache_dir, model), pr, info, model)
    return pr


def write(path, pr, info, model):
    """Write a primitive to Parquet atomically (rows = x0 nodes; grid and error in metadata)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    nz = pr.nz
    cols = {"x0": pr.xn, "ln_v_inf": pr.lnv, "ln_S": pr.lnS, "z_start": pr.zs,
            "ln_kappa": pr.lk}
    arrays = {k: pa.array(v) for k, v in cols.items()}
    for q, k in enumerate(("L", "D1", "D2")):
        arrays[k] = pa.FixedSizeListArray.from_arrays(
            pa.array(np.ascontiguousarray(pr.C[:, :, q]).ravel()), nz)
    meta = {"kind": "squeeze_time_primitive", "version": PRIMITIVE_VERSION, "key": model.key(),
            "theory": model.theory, "z0": pr.z0, "dz": pr.dz, "nz": nz, "v_ext": pr.v_ext,
            "c": pr.c, "d": pr.d, "info": info,
            "units": "reduced: x0 = ln(p0/E*), z = ln(u/u_inf - 1), T in tau0 = 3 eta R^2/(2 h_rms^2 p0)",
            "columns": {"L": "ln T", "D1": "d ln T/dz", "D2": "d2 ln T/dz2"}}
    table = pa.table(arrays).replace_schema_metadata(
        {METADATA_KEY: json.dumps(meta, sort_keys=True).encode()})
    with atomic_path(path) as tmp:
        pq.write_table(table, tmp, write_page_checksum=True)
    return Path(path)


def read_checked(path, what):
    """(pyarrow table, metadata dict) of a file written with page checksums; ValueError naming
    ``what`` and the path if it cannot be read."""
    import pyarrow.parquet as pq

    try:
        table = pq.read_table(path, page_checksum_verification=True)
        return table, json.loads(table.schema.metadata[METADATA_KEY])
    except Exception as exc:  # noqa: BLE001 - pyarrow raises several types
        raise ValueError(f"{what} file {str(path)!r} cannot be read ({exc})") from None


def read(path, expect_key=None):
    """Read a primitive written by :func:`write`; ValueError if damaged or not the expected."""
    table, meta = read_checked(path, "primitive")
    if meta.get("version") != PRIMITIVE_VERSION or (expect_key and meta.get("key") != expect_key):
        raise ValueError(f"primitive file {str(path)!r} does not belong to these tables")
    nz = int(meta["nz"])
    col = {k: np.ascontiguousarray(table.column(k).to_numpy(), dtype=np.float64)
           for k in ("x0", "ln_v_inf", "ln_S", "z_start", "ln_kappa")}
    mats = {k: np.ascontiguousarray(table.column(k).combine_chunks().flatten().to_numpy()
                                    .reshape(-1, nz), dtype=np.float64) for k in ("L", "D1", "D2")}
    xn = col["x0"]
    C = np.ascontiguousarray(np.stack([mats["L"], mats["D1"], mats["D2"]], axis=2))
    pr = readonly_fields(Primitive(xn, *_index_map(xn), lagrange_denominators(xn),
                                   float(meta["z0"]), float(meta["dz"]), nz, C,
                                   col["ln_v_inf"], col["ln_S"], col["z_start"], col["ln_kappa"],
                                   float(meta["v_ext"]), float(meta["c"]), float(meta["d"])))
    return pr, meta["info"]
