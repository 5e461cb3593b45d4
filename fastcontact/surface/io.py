"""Spectrum files in and out: fastcontact tables, contact.engineering downloads, and the PSD
results of SurfaceTopography.

Everything returned is a :class:`~fastcontact.surface.psd.TabulatedPSD` in the Persson
convention and SI units. Conventions: Persson ``C = (2π)⁻² ∫ d²x ⟨h(x)h(0)⟩ e^{-iq·x}``
(h_rms² = 2π∫qC dq); SurfaceTopography / contact.engineering ``C_ST = (2π)² C`` for the 2-D
(isotropic) PSD and ``C1D_ST = 2π C1D`` for the 1-D PSD of profiles (T.D.B. Jacobs,
T. Junge, L. Pastewka, Surf. Topogr. Metrol. Prop. 5, 013001 (2017),
doi:10.1088/2051-672X/aa51f8). contact.engineering's "q/π × 2D PSD" series [m³] is
``q C_ST / π``, i.e. ``C = y / (4π q)``. Files are parsed as plain data (pandas / pyarrow /
openpyxl readers); nothing is unpickled or evaluated.
"""
from __future__ import annotations

import gzip
import math
import os
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from .._core.io import atomic_path
from .._core.validate import as_float_array, check_int
from .._core.vocab import CONVENTIONS
from .abel import abel_fit
from .psd import PSD, TabulatedPSD

__all__ = ["read_psd", "write_psd", "read_topography", "psd_from_surface_topography",
           "CONVENTION_KEY", "CE_2D_SERIES", "TOPOGRAPHY_EXTRA"]

#: Parquet key-value metadata key holding the convention of the stored C column
CONVENTION_KEY = b"fastcontact.convention"
#: how to install the optional SurfaceTopography reader
TOPOGRAPHY_EXTRA = 'pip install "fastcontact[topography]"'
#: name of contact.engineering's isotropic 2-D series (values q C_ST / π [m³])
CE_2D_SERIES = "q/π × 2D PSD"
_SUFFIXES = {".csv": "csv", ".csv.gz": "csv.gz", ".txt": "txt", ".dat": "txt",
             ".parquet": "parquet", ".pq": "parquet", ".xlsx": "xlsx"}
_PREFIX = {"": 1.0, "k": 1e3, "c": 1e-2, "d": 1e-1, "m": 1e-3, "µ": 1e-6, "μ": 1e-6,
           "u": 1e-6, "n": 1e-9, "p": 1e-12}
_SUPER = str.maketrans({"⁻": "-", "¹": "1", "²": "2", "³": "3", "⁴": "4"})


def _check_convention(convention):
    if not isinstance(convention, str) or convention not in CONVENTIONS:
        raise ValueError(
            f"convention = {convention!r} is invalid: must be one of {sorted(CONVENTIONS)} "
            f"and is required (\"persson\": C = (2π)^-2 ∫<hh>e^-iqx, h_rms² = 2π∫qC dq; "
            f"\"surface_topography\" / contact.engineering: (2π)² times Persson's C)")
    return convention


def _kind(path):
    name = Path(path).name.lower()
    for suffix in sorted(_SUFFIXES, key=len, reverse=True):
        if name.endswith(suffix):
            return _SUFFIXES[suffix]
    raise ValueError(f"path = {str(path)!r} is invalid: must end in one of "
                     f"{', '.join(_SUFFIXES)}")


# ============================================================================ units
def _length_power(unit: str, what: str):
    """(factor to SI, power of length) of a unit string such as ``1/m``, ``m³``, ``µm^3``."""
    u = unit.strip().translate(_SUPER).replace("**", "^").replace(" ", "")
    sign = 1
    if u.startswith("1/"):
        u, sign = u[2:], -1
    m = re.fullmatch(r"([kcdmµμunp]?)m(?:\^?(-?\d+))?", u)
    if not m:
        raise ValueError(f"{what} unit = {unit!r} is invalid: must be a power of a length "
                         f"unit (e.g. '1/m', 'm³', 'µm^3')")
    power = sign * int(m.group(2) or 1)
    return _PREFIX[m.group(1)] ** power, power


def _header_unit(column: str):
    """The unit in a column header such as ``PSD (m³)`` or ``C [um^4]``, or None."""
    m = re.search(r"[(\[]([^()\[\]]*)[)\]]\s*$", column)
    return m.group(1) if m else None


def _column_scale(col, want, path):
    """SI factor of a table column from the unit in its header (1 without one); a C column
    in length³ is a 1-D spectrum and is refused."""
    unit = _header_unit(col)
    if unit is None:
        return 1.0
    f, power = _length_power(unit, f"column {col!r}")
    if power != want:
        what = ("a 1-D spectrum [length³], never taken for the isotropic 2-D C [length⁴]"
                if want == 4 and power == 3 else f"not length^{want}")
        raise ValueError(f"C_col = {col!r} of {path!r} is invalid: {what}" if want == 4 else
                         f"q_col = {col!r} of {path!r} is invalid: {what}")
    return f


# ============================================================================ contact.engineering
def _ce_to_persson(name, q, y, x_unit, y_unit, path):
    """Persson-convention (q [1/m], C [m^4]) of one contact.engineering series."""
    fx, px = _length_power(x_unit, "wavevector")
    fy, py = _length_power(y_unit, "PSD")
    if px != -1:
        raise ValueError(f"wavevector unit = {x_unit!r} of {path!r} is invalid: must be 1/length")
    q, y = q * fx, y * fy
    low = name.lower()
    if "1d psd" in low or ("2d" not in low and py == 3):
        raise ValueError(
            f"series = {name!r} of {path!r} is invalid: it is a 1-D spectrum of profiles "
            f"[m³], never taken for the isotropic 2-D spectrum; choose series={CE_2D_SERIES!r}, "
            f"or pass the 1-D values to psd_from_surface_topography(q, C, dim=1)")
    if "q/π" in low and py == 3:
        return q, y / (4.0 * math.pi * q)            # y = q C_ST / π, C_ST = (2π)² C
    if py == 4:
        return q, y * CONVENTIONS["surface_topography"]
    raise ValueError(f"PSD unit = {y_unit!r} of series {name!r} in {path!r} is invalid: must be "
                     f"length³ ('q/π × 2D PSD') or length⁴ (2-D PSD)")


def _pick(blocks, series, subject, path):
    """The one (subject, name) block of a contact.engineering file to read."""
    names = sorted({b[1] for b in blocks})
    if series is None:
        series = CE_2D_SERIES if CE_2D_SERIES in names else None
        if series is None:
            raise ValueError(f"series = None is invalid for {path!r}: the file has no "
                             f"{CE_2D_SERIES!r} series (a line scan has only 1-D spectra); "
                             f"series present: {names}")
    chosen = [b for b in blocks if b[1] == series]
    if not chosen:
        raise ValueError(f"series = {series!r} is invalid for {path!r}: must be one of {names}")
    subjects = sorted({b[0] for b in chosen})
    if subject is None and len(subjects) > 1:
        raise ValueError(f"subject = None is invalid for {path!r}: the file holds {series!r} "
                         f"for {len(subjects)} measurements; pass subject= one of {subjects}")
    if subject is not None:
        chosen = [b for b in chosen if b[0] == subject]
        if not chosen:
            raise ValueError(f"subject = {subject!r} is invalid for {path!r}: must be one of "
                             f"{subjects}")
    return chosen[0]


def _read_ce_csv(path, sep, series, subject):
    df = pd.read_csv(path, sep=sep, comment=None)
    cols = [str(c) for c in df.columns]
    qc = next((c for c in cols if c.lower().startswith("wavevector")), None)
    yc = next((c for c in cols if c.startswith("PSD")), None)
    if qc is None or yc is None:
        raise ValueError(f"path = {path!r} is invalid: a contact.engineering CSV needs "
                         f"'Wavevector (unit)' and 'PSD (unit)' columns (columns: {cols})")
    subj = df["Subject name"].astype(str) if "Subject name" in df else pd.Series("", index=df.index)
    blocks = [(s, n, g) for (s, n), g in df.groupby([subj, df["Data series"].astype(str)],
                                                     sort=False)]
    s, n, g = _pick([(s, n, g) for s, n, g in blocks], series, subject, path)
    return n, g[qc].to_numpy(float), g[yc].to_numpy(float), _header_unit(qc), _header_unit(yc)


_COLUMNS = re.compile(r"^#\s*Columns:\s*([^,]+\(([^)]*)\))\s*,\s*([^,]+\(([^)]*)\))")


def _read_ce_txt(path, series, subject):
    """Blocks of contact.engineering's txt download: a ``# name / # --- / # Columns: ...``
    header per series (``# type: subject / # ===`` per measurement), rows of numbers."""
    blocks, cur, subj, prev = [], None, "", []
    with open(path, encoding="utf-8", errors="replace") as fh:
        for raw in fh:
            line = raw.strip()
            if line.startswith("#"):
                text = line.lstrip("#").strip()
                if set(text) == {"="} and prev:
                    subj = prev[-1].split(": ", 1)[-1]
                m = _COLUMNS.match(line)
                if m and len(prev) >= 2 and set(prev[-1]) == {"-"}:
                    cur = [subj, prev[-2], m.group(2), m.group(4), []]
                    blocks.append(cur)
                prev.append(text)
                continue
            if line and cur is not None:
                cur[4].append(line.split()[:2])
    if not blocks:
        return None
    s, n, xu, yu, rows = _pick([(b[0], b[1], b) for b in blocks], series, subject, path)[2]
    data = np.asarray(rows, dtype=float).reshape(-1, 2)
    return n, data[:, 0], data[:, 1], xu, yu


def _read_ce_xlsx(path, series, subject):
    sheets = pd.read_excel(path, sheet_name=None, header=None)
    index = sheets.get("INDEX")
    if index is None:
        raise ValueError(f"path = {path!r} is invalid: no INDEX sheet (not a contact.engineering "
                         f"download)")
    head = [str(v) for v in index.iloc[0]]
    blocks = []
    for _, row in index.iloc[1:].iterrows():
        rec = dict(zip(head, row))
        m = re.search(r"sheet '([^']+)'", str(rec.get("Link", "")))
        if m:
            blocks.append((str(rec.get("Subject name", "")), str(rec.get("Data series", "")),
                           m.group(1)))
    s, n, sheet = _pick(blocks, series, subject, path)
    df = pd.read_excel(path, sheet_name=sheet, header=9, index_col=0)
    cols = [str(c) for c in df.columns]
    return (n, df[cols[0]].to_numpy(float), df[cols[1]].to_numpy(float),
            _header_unit(cols[0]), _header_unit(cols[1]))


def _first_line(path, kind):
    opener = gzip.open if kind == "csv.gz" else open
    with opener(path, "rt", encoding="utf-8", errors="replace") as fh:
        for line in fh:
            if line.strip() and not line.lstrip().startswith("#"):
                return line
    return ""


def _read_contact_engineering(path, kind, convention, series, subject):
    """(q, C Persson) of a contact.engineering download, or None if the file is not one."""
    if kind == "xlsx":
        got = _read_ce_xlsx(path, series, subject)
    elif kind == "txt":
        got = _read_ce_txt(path, series, subject)
    else:
        head = _first_line(path, kind)
        if "Data series" not in head:
            return None
        got = _read_ce_csv(path, ";" if head.count(";") > head.count(",") else ",",
                           series, subject)
    if got is None:
        return None
    if convention not in (None, "surface_topography"):
        raise ValueError(f"convention = {convention!r} is invalid for {path!r}: a "
                         f"contact.engineering download is in SurfaceTopography's convention; "
                         f"pass convention=None or 'surface_topography'")
    name, q, y, xu, yu = got
    if xu is None or yu is None:
        raise ValueError(f"path = {path!r} is invalid: the series {name!r} states no units")
    keep = np.isfinite(q) & np.isfinite(y)          # bins without data are NaN in downloads
    return _ce_to_persson(name, q[keep], y[keep], xu, yu, path)


# ============================================================================ plain tables
def _read_table(path, kind, convention, q_col, C_col):
    """(q, C) columns of a fastcontact CSV / Parquet / two-column txt table, as stored."""
    if kind == "txt":
        try:
            data = np.loadtxt(path, comments="#", ndmin=2)
        except ValueError as exc:
            raise ValueError(f"path = {path!r} is invalid: cannot parse as two columns of "
                             f"numbers ({exc})") from None
        if data.shape[1] < 2:
            raise ValueError(f"path = {path!r} is invalid: needs two columns (q, C)")
        return data[:, 0], data[:, 1], ["q", "C"]
    if kind in ("csv", "csv.gz"):
        try:
            df = pd.read_csv(path, comment="#", skipinitialspace=True, sep=None,
                             engine="python", compression="gzip" if kind == "csv.gz" else None)
        except Exception as exc:  # noqa: BLE001 - malformed text, empty file, ...
            raise ValueError(f"path = {path!r} is invalid: cannot parse as CSV ({exc})") from None
        df.columns = [str(c).strip() for c in df.columns]
        columns, get = list(df.columns), (lambda name: df[name].to_numpy())
    else:
        try:
            table = pq.read_table(path)
        except Exception as exc:  # noqa: BLE001
            raise ValueError(f"path = {path!r} is invalid: cannot read as Parquet ({exc})") from None
        stored = (table.schema.metadata or {}).get(CONVENTION_KEY)
        if stored is not None and stored.decode("utf-8", "replace") != convention:
            stored = stored.decode("utf-8", "replace")
            raise ValueError(f"convention = {convention!r} is invalid for {path!r}: the file's "
                             f"metadata {CONVENTION_KEY.decode()} says {stored!r}; pass "
                             f"convention={stored!r}")
        columns = list(table.column_names)
        get = (lambda name: table.column(name).to_numpy(zero_copy_only=False))
    for nm, col in (("q_col", q_col), ("C_col", C_col)):
        if col not in columns:
            raise ValueError(f"{nm} = {col!r} is invalid for {path!r}: no such column "
                             f"(columns: {columns})")
    return get(q_col), get(C_col), columns


def read_psd(path, convention=None, *, q_col=None, C_col=None, series=None, subject=None):
    """Read a spectrum file into a :class:`TabulatedPSD` (Persson convention, SI).

    Parameters
    ----------
    path : str or Path
        * a contact.engineering PSD download — ``.csv`` (``;`` or ``,`` separated, series
          stacked with a "Data series" column), ``.txt`` (``#``-commented blocks, one per
          series) or ``.xlsx`` (INDEX sheet + one sheet per series). Units are read from the
          column headers; the "q/π × 2D PSD" series [m³] is used (``C = y / (4π q)``);
        * a table: ``.csv``/``.csv.gz`` (header row, ``,`` or ``;``), ``.parquet``/``.pq``,
          or a ``#``-commented two-column ``.txt``; q [1/m] strictly increasing, C [m^4].
    convention : {"persson", "surface_topography"}
        **Required for tables**: the normalisation of the C column (SurfaceTopography's C is
        (2π)² times Persson's). A Parquet file's metadata ``fastcontact.convention`` must
        agree. For a contact.engineering download it is known: None or
        "surface_topography".
    q_col, C_col : str, optional
        Column names of a CSV / Parquet table (default "q" and "C"). A unit in the header,
        e.g. ``"q (1/um)"``, ``"C [um^4]"``, is converted to SI; a C column in length³ (a
        1-D spectrum) is refused.
    series : str, optional
        Series of a contact.engineering download (default "q/π × 2D PSD"). A 1-D series
        ("1D PSD along x", ...) is refused: it is never taken for the 2-D spectrum.
    subject : str, optional
        Measurement name, when a download holds several.

    Returns
    -------
    TabulatedPSD
        Bins without data (NaN in downloads) are dropped.
    """
    path = os.fspath(path)
    kind = _kind(path)
    if not os.path.isfile(path):
        raise ValueError(f"path = {path!r} is invalid: no such file")
    got = _read_contact_engineering(path, kind, convention, series, subject)
    if got is not None:
        try:
            return TabulatedPSD(got[0], got[1], convention="persson")
        except ValueError as exc:
            raise ValueError(f"{exc} (series of {path!r})") from None
    if kind == "xlsx":
        raise ValueError(f"path = {path!r} is invalid: not a contact.engineering download")
    convention = _check_convention(convention)
    q_col = "q" if q_col is None else q_col
    C_col = "C" if C_col is None else C_col
    for nm, v in (("q_col", q_col), ("C_col", C_col)):
        if not isinstance(v, str) or not v:
            raise ValueError(f"{nm} = {v!r} is invalid: must be a non-empty column name")
    q, C, _ = _read_table(path, kind, convention, q_col, C_col)
    scale = {"q": _column_scale(q_col, -1, path), "C": _column_scale(C_col, 4, path)}
    out = []
    for nm, raw in (("q", q), ("C", C)):
        try:
            out.append(np.asarray(raw, dtype=np.float64) * scale[nm])
        except (TypeError, ValueError):
            raise ValueError(f"{nm} = column of {path!r} is invalid: must hold numbers "
                             f"only") from None
    try:
        return TabulatedPSD(out[0], out[1], convention=convention)
    except ValueError as exc:
        raise ValueError(f"{exc} (column {q_col!r}/{C_col!r} of {path!r})") from None


# ============================================================================ SurfaceTopography
def read_topography(path, *, unit=None, **kwargs):
    """A measured topography file (AFM, optical profilometer, stylus, ...) as a
    SurfaceTopography container, ready for :func:`~fastcontact.surface.topography.psd_from_heights`.

    Parameters
    ----------
    path : str or Path
        Any format SurfaceTopography reads (``.nc``, ``.sur``, ``.ibw``, ``.opd``, ``.x3p``,
        ``.txt`` height matrices, ...).
    unit : str, optional
        Length unit of the file when it states none (e.g. ``"um"``).
    **kwargs
        Passed to ``SurfaceTopography.read_topography`` (e.g. ``physical_sizes``,
        ``periodic``, ``channel_index``).

    Raises
    ------
    ImportError
        One line naming the optional extra when SurfaceTopography is not installed.
    """
    try:
        import SurfaceTopography
    except ImportError:
        raise ImportError(f"reading topography files needs SurfaceTopography: "
                          f"{TOPOGRAPHY_EXTRA}") from None
    if unit is not None:
        kwargs["unit"] = unit
    path = os.fspath(path)
    if not os.path.isfile(path):
        raise ValueError(f"path = {path!r} is invalid: no such file")
    return SurfaceTopography.read_topography(path, **kwargs)


def psd_from_surface_topography(q, C, *, dim, unit="m"):
    """A PSD computed by SurfaceTopography, as a Persson-convention :class:`TabulatedPSD`.

    Parameters
    ----------
    q : array_like [1/unit]
        Wavevectors as returned (masked bins — bins without data — are dropped).
    C : array_like [unit^4] (dim=2) or [unit^3] (dim=1)
        ``power_spectrum_from_area`` (dim=2, C_ST = (2π)² C) or
        ``power_spectrum_from_profile`` (dim=1, C1D_ST = 2π C1D) output.
    dim : {1, 2}
        **Required**: which spectrum it is. A 1-D spectrum is converted to the isotropic 2-D
        C by the regularised Abel fit (:func:`~fastcontact.surface.abel.abel_fit`, weights
        ∝ the number of FFT values per bin, assuming log-spaced bins from the first one).
    unit : str
        Length unit of the container the spectrum came from (``topography.unit``).
    """
    dim = check_int("dim", dim, 1, 2)
    mask = np.ma.getmaskarray(q) | np.ma.getmaskarray(C)
    q = as_float_array("q", np.ma.getdata(q)[~mask])
    C = as_float_array("C", np.ma.getdata(C)[~mask])
    keep = q > 0                                   # q = 0 of resampling_method=None output
    q, C = q[keep], C[keep]
    fq, _ = _length_power(f"1/{unit}", "q")
    fc, _ = _length_power(f"{unit}^{dim + 2}", "C")
    q, C = q * fq, C * fc
    if dim == 2:
        return TabulatedPSD(q, C, convention="surface_topography")
    d = C / (2.0 * math.pi)
    edges = np.sqrt(q[1:] * q[:-1])
    width = np.diff(np.concatenate(([q[0] ** 2 / edges[0]], edges, [q[-1] ** 2 / edges[-1]])))
    w = np.maximum(1.0, width / q[0])
    return TabulatedPSD(q, abel_fit(q, d, w), convention="persson")


# ============================================================================ writing
def _samples(psd):
    """(q, C_persson) samples whose log-log interpolant is exactly ``psd``."""
    if isinstance(psd, TabulatedPSD):
        return psd.q_samples.copy(), psd.C_samples.copy()
    qb, c, e = psd.qb, psd.c, psd.e
    end = c * (qb[1:] / qb[:-1]) ** e                  # C at the right end of each segment
    jump = np.abs(end[:-1] / c[1:] - 1.0)
    if np.any(jump > 1e-9):
        i = int(np.argmax(jump > 1e-9))
        raise ValueError(f"psd = {psd!r} is invalid for a table: C jumps at q = {qb[i + 1]!r} "
                         f"[1/m], which log-log interpolated samples cannot represent")
    return qb.copy(), np.concatenate((c, end[-1:]))


def write_psd(psd, path, convention="persson"):
    """Write ``psd`` as a table of samples (CSV or Parquet, by the suffix of ``path``).

    The samples are the spectrum's tabulated points (a :class:`TabulatedPSD`) or its power-law
    breakpoints (e.g. a SelfAffinePSD: q0, q_roll, q1), so that :func:`read_psd` reproduces it
    exactly (to float round-off). C is written in ``convention``; Parquet files also record it
    in the metadata key ``fastcontact.convention``. CSV: header ``q,C``, 17 significant
    digits. Written atomically (a temporary name in the same folder, then renamed).
    """
    if not isinstance(psd, PSD):
        raise ValueError(f"psd = {psd!r} is invalid: must be a fastcontact PSD object")
    convention = _check_convention(convention)
    path = os.fspath(path)
    kind = _kind(path)
    if kind not in ("csv", "csv.gz", "parquet"):
        raise ValueError(f"path = {path!r} is invalid: must end in .csv, .csv.gz, .parquet "
                         f"or .pq")
    q, C = _samples(psd)
    C = C / CONVENTIONS[convention]
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        raise ValueError(f"path = {path!r} is invalid: folder {folder!r} does not exist")
    with atomic_path(path) as tmp:
        if kind in ("csv", "csv.gz"):
            pd.DataFrame({"q": q, "C": C}).to_csv(
                tmp, index=False, float_format="%.17g",
                compression="gzip" if kind == "csv.gz" else None)
        else:
            table = pa.table({"q": pa.array(q, pa.float64()), "C": pa.array(C, pa.float64())})
            table = table.replace_schema_metadata({
                CONVENTION_KEY: convention.encode(),
                b"fastcontact.units": b"q [1/m], C [m^4]",
            })
            pq.write_table(table, tmp)
    return path
