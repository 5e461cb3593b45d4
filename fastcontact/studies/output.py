"""Files of a run: Parquet with the unit of every column, streamed in blocks and renamed into
place; JSON and text written atomically; a summary with units."""
from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.parquet as pq

from .._core.io import atomic_path, publish, temp_beside, write_bytes_atomic
from .._core.jsonable import json_default
from .._core.vocab import METADATA_KEY
from .kinds import column_units
from .schema import input_units

__all__ = ["ParquetStream", "write_parquet_atomic", "write_json_atomic", "json_default",
           "column_summary"]


_json_default = json_default


def _atomic_write_bytes(path, data: bytes):
    return write_bytes_atomic(path, data)


def write_json_atomic(path, obj) -> Path:
    """Write ``obj`` as indented, key-sorted JSON to ``path`` atomically."""
    return write_bytes_atomic(Path(path), json.dumps(obj, indent=2, sort_keys=True,
                                                     default=json_default).encode())


def _table(df, units, metadata, schema=None):
    """Arrow table of ``df`` with the unit of every column as field metadata (known columns
    get their SI unit even without ``units``: case inputs and engine results)."""
    table = pa.Table.from_pandas(df, preserve_index=False)
    if schema is not None:
        return table.cast(schema)
    known = {**input_units(), **{k: u for k, u in column_units(df.columns).items() if u}}
    units = {**known, **(units or {}), **df.attrs.get("units", {})}
    fields = [f.with_metadata({"unit": units.get(f.name, "")}) for f in table.schema]
    meta = dict(table.schema.metadata or {})
    if metadata is not None:
        meta[METADATA_KEY] = json.dumps(dict(metadata, units={f.name: units.get(f.name, "")
                                                              for f in fields}),
                                        sort_keys=True, default=json_default).encode()
    return table.cast(pa.schema(fields, metadata=meta))


def write_parquet_atomic(df, path, metadata: dict | None = None, units: dict | None = None):
    """Write ``df`` to ``path`` atomically, with JSON ``metadata`` under the ``fastcontact``
    key and each column's unit (``units``, else ``df.attrs["units"]``) as field metadata."""
    path = Path(path)
    table = _table(df, units, metadata)
    with atomic_path(path) as tmp:
        pq.write_table(table, tmp)
    return path


class ParquetStream:
    """Write a Parquet file block by block: a temporary file beside ``path``, renamed into
    place by :meth:`close` (a reader never sees a partial file).

    Parameters
    ----------
    path : path-like
    metadata : dict
        Stored as JSON under the ``fastcontact`` key (the units are added).
    units : dict
        SI unit of each column (field metadata ``unit``).
    """

    def __init__(self, path, metadata=None, units=None):
        self.path = Path(path)
        self.metadata, self.units = metadata, units
        self.writer, self.schema, self.rows = None, None, 0
        self.tmp = temp_beside(self.path)

    def write(self, df):
        """Append the rows of ``df`` (same columns and types as the first block)."""
        table = _table(df, self.units, self.metadata, self.schema)
        if self.writer is None:
            self.schema = table.schema
            self.writer = pq.ParquetWriter(self.tmp, self.schema)
        self.writer.write_table(table)
        self.rows += table.num_rows

    def close(self) -> Path:
        """Finish the file and move it into place."""
        if self.writer is None:
            raise ValueError(f"{self.path}: no rows were written")
        self.writer.close()
        publish(self.tmp, self.path)
        return self.path

    def abort(self):
        """Drop the temporary file."""
        if self.writer is not None:
            self.writer.close()
        if os.path.exists(self.tmp):
            os.unlink(self.tmp)


class _Stats:
    """Streaming min / max / true-count of one column over one group, and its median
    (exact up to ``exact`` values; beyond that the median of an even sample of them)."""

    def __init__(self, n, exact=1_000_000):
        self.step = max(1, -(-n // exact))
        self.lo, self.hi, self.true, self.rows, self.sample, self.seen = (
            np.inf, -np.inf, 0, 0, [], 0)

    def add_num(self, v):
        w = v[np.isfinite(v)]
        if w.size:
            self.lo, self.hi = min(self.lo, w.min()), max(self.hi, w.max())
            first = (-self.seen) % self.step
            self.sample.append(w[first::self.step].copy())
            self.seen += w.size

    def num(self):
        if not self.seen:
            return None
        return self.lo, float(np.median(np.concatenate(self.sample))), self.hi


def _batches(pf, column, groups):
    """Yield (group, values) pieces of ``column`` read batch by batch."""
    start = 0
    for batch in pf.iter_batches(columns=[column], batch_size=1 << 18):
        col = batch.column(0)
        stop = start + len(col)
        for g, a, b in groups:
            lo, hi = max(a, start), min(b, stop)
            if lo < hi:
                yield g, col.slice(lo - start, hi - lo)
        start = stop


def column_summary(path, columns, groups):
    """Per-group min / median / max (numbers) or true-count (flags) of ``columns`` of a
    Parquet file, streamed (memory bounded whatever the file size).

    Parameters
    ----------
    path : path-like
    columns : list of str
    groups : list of (name, start, stop)
        Row ranges of the groups (the surfaces, written one after another).

    Returns
    -------
    dict
        ``{group: [(column, kind, values)]}`` with kind ``"num"`` → (min, median, max) of the
        finite values or None, ``"bool"`` → (true count, rows). Medians of groups over 1e6
        rows are those of an even sample of 1e6 values.
    """
    # pre_buffer=False: pyarrow's default pre-buffers the column of every row group it will
    # read, which held ~10 B per row (104 MB of pool for 1e7 rows); unbuffered reads hold one
    # batch (pool peak 9.6 MB at 1e6 and at 1e7 rows)
    pf = pq.ParquetFile(path, pre_buffer=False)
    types = {f.name: f.type for f in pf.schema_arrow}
    out = {g: [] for g, _, _ in groups}
    for c in columns:
        t = types.get(c)
        if t is None or not (pa.types.is_boolean(t) or pa.types.is_floating(t)):
            continue
        stats = {g: _Stats(b - a) for g, a, b in groups}
        for g, part in _batches(pf, c, groups):
            if pa.types.is_boolean(t):
                stats[g].true += int(pc.sum(part).as_py() or 0)
            else:
                stats[g].add_num(part.to_numpy(zero_copy_only=False))
        for g, a, b in groups:
            st = stats[g]
            out[g].append((c, "bool", (st.true, b - a)) if pa.types.is_boolean(t)
                          else (c, "num", st.num()))
    return out
