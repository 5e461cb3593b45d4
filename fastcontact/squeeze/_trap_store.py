"""The trapped side's time primitive on disk, beside the equilibrium side's.

Part of :mod:`fastcontact.squeeze.primitive`. One Parquet file per (tables, theory), in the
directory :func:`~._primitive_store.set_primitive_cache` configured, keyed by the model's
content key: rows = the s = ln(x0 - x_trap) nodes, the two pieces' node columns (lower: T,
dT/dz, d²T/dz²; upper: ln T and its z-derivatives) as fixed-size lists, the grid, version,
key and the measured interpolation error in the metadata. Written atomically and read back
with page checksums; a damaged or foreign file raises ValueError (then rebuilt).
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from .._core.io import atomic_path
from .._core.vocab import METADATA_KEY
from ..kernels.readonly import readonly_fields
from . import _trap_primitive as tpm
from ._primitive_store import _CACHE_ATTR, read_checked

__all__ = ["load_or_build", "write", "read", "trap_path", "TRAP_VERSION"]

#: format version of the stored trapped-side primitives (another version is rebuilt; 2: rows
#: from 1e-8 above the trap pressure in ln p0, were from 1e-4)
TRAP_VERSION = 2
_PIECES = (("lo", ("T", "dT", "d2T")), ("hi", ("L", "D1", "D2")))


def trap_path(directory, model) -> Path:
    """File of ``model``'s trapped-side primitive in ``directory``."""
    return Path(directory) / f"squeeze_trapped_{model.theory}_{model.key()}.parquet"


def load_or_build(model):
    """(TrapPrimitive, info) of ``model``: read from the tables' primitive cache directory if
    there, else built with its interpolation error measured (~5 ms: the measurement shares
    the build's table lookups) and written there when one is configured."""
    cache_dir = getattr(model.tables, _CACHE_ATTR, None)
    if cache_dir is not None:
        path = trap_path(cache_dir, model)
        if path.is_file():
            try:
                return read(path, expect_key=model.key())
            except ValueError:
                pass  # damaged or stale: rebuild and overwrite
    tp, info = tpm.build(model, check=True)
    if cache_dir is not None and info.get("rows", 0) > 0:
        write(trap_path(cache_dir, model), tp, info, model)
    return tp, info


def write(path, tp, info, model):
    """Write a trapped-side primitive to Parquet atomically."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    arrays = {"s": pa.array(tp.lo.xn)}
    grid = {}
    for name, cols in _PIECES:
        pr = getattr(tp, name)
        for q, col in enumerate(cols):
            arrays[f"{name}_{col}"] = pa.FixedSizeListArray.from_arrays(
                pa.array(np.ascontiguousarray(pr.C[:, :, q]).ravel()), pr.nz)
        grid[name] = {"z0": pr.z0, "dz": pr.dz, "nz": pr.nz, "v_ext": pr.v_ext}
    r = tp.rows
    meta = {"kind": "squeeze_trapped_primitive", "version": TRAP_VERSION, "key": model.key(),
            "theory": model.theory, "grid": grid, "c": tp.hi.c, "d": tp.hi.d,
            "rows": {"x_trap": r.x_trap, "x_lo": r.x_lo, "x_hi": r.x_hi, "lnvb": r.lnvb,
                     "z_split": r.z_split},
            "info": info,
            "units": "reduced: s = ln(ln(p0/E*) - ln(p_trap/E*)), z = ln(u/u_trap - 1), T in "
                     "tau0 = 3 eta R^2/(2 h_rms^2 p0)",
            "columns": {"lo_T": "T", "lo_dT": "dT/dz", "lo_d2T": "d2T/dz2", "hi_L": "ln T",
                        "hi_D1": "d ln T/dz", "hi_D2": "d2 ln T/dz2"}}
    table = pa.table(arrays).replace_schema_metadata(
        {METADATA_KEY: json.dumps(meta, sort_keys=True).encode()})
    with atomic_path(path) as tmp:
        pq.write_table(table, tmp, write_page_checksum=True)
    return Path(path)


def read(path, expect_key=None):
    """Read a file written by :func:`write`: (TrapPrimitive, info); ValueError if damaged or
    not the expected one."""
    table, meta = read_checked(path, "trapped primitive")
    if (meta.get("kind") != "squeeze_trapped_primitive" or meta.get("version") != TRAP_VERSION
            or (expect_key and meta.get("key") != expect_key)):
        raise ValueError(f"trapped primitive file {str(path)!r} does not belong to these tables")
    sn = np.ascontiguousarray(table.column("s").to_numpy(), dtype=np.float64)
    pieces = {}
    for name, cols in _PIECES:
        g = meta["grid"][name]
        nz = int(g["nz"])
        C = np.ascontiguousarray(np.stack(
            [table.column(f"{name}_{col}").combine_chunks().flatten().to_numpy()
             .reshape(-1, nz) for col in cols], axis=2), dtype=np.float64)
        pieces[name] = tpm.piece(sn, g["z0"], g["dz"], C, float(g["v_ext"]), float(meta["c"]),
                                 float(meta["d"]))
    r = meta["rows"]
    rows = readonly_fields(tpm.TrapRows(float(r["x_trap"]), float(r["x_lo"]), float(r["x_hi"]),
                                        float(r["lnvb"]), float(r["z_split"])))
    return tpm.TrapPrimitive(pieces["lo"], pieces["hi"], rows), meta["info"]
