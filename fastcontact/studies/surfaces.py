"""The ``[surfaces.<name>]`` of a scene: a table file (checked against the surface the scene
says it holds), a PSD file, or self-affine parameters."""
from __future__ import annotations

import math
from pathlib import Path

from .._core.vocab import CONVENTIONS
from ..tables.cache import read_table_metadata, surface_mismatch
from ..tables.defaults import DEFAULT_SURFACES, default_surface
from .examples import default_table_path
from .scene import SurfaceSpec
from .schema import (SELF_AFFINE_KEYS, SURFACE_KEYS, did_you_mean, parse_scalar as _parse_scalar,
                     try_parse as _try)

__all__ = ["parse_surfaces"]


def _resolve_table_file(value, base):
    p = Path(value).expanduser()
    cand = p if p.is_absolute() else base / p
    return cand if cand.is_file() else default_table_path(value)


def _self_affine_params(pre, sd, problems):
    params = {}
    for k in SELF_AFFINE_KEYS:
        if k in sd:
            x = _try(problems, _parse_scalar, f"{pre}.{k}", sd[k], SURFACE_KEYS[k])
            if x is not None:
                params[k] = x
        elif k != "q_roll":
            problems.append(f"{pre}.{k} is missing (self-affine surface: h_rms, hurst, q0, q1)")
    return params


def _expected_surface(pre, v, sd, path, problems):
    """The PSD the scene says a table file holds (its description, or the embedded
    default of that name), or None if it says nothing."""
    if any(k in sd for k in SELF_AFFINE_KEYS):
        params = _self_affine_params(pre, sd, problems)
        if len(params) >= 4:
            return _try(problems, lambda: SurfaceSpec("x", "self_affine", params=params).psd())
        return None
    name = Path(str(v)).name.removesuffix(".parquet")
    try:
        is_default = path.resolve() == default_table_path(name).resolve()
    except FileNotFoundError:
        is_default = False
    return default_surface(name) if is_default and name in DEFAULT_SURFACES else None


def _table_surface(pre, name, sd, base, theories, topts_given, problems, label):
    v, n0 = sd["table"], len(problems)
    if "convention" in sd or "psd" in sd:
        problems.append(f"{pre}: a table surface takes table = ... (and optionally the surface's "
                        f"h_rms, hurst, q0, q1 [, q_roll] to check it), not psd/convention")
    if not isinstance(v, str):
        problems.append(f"{pre}.table = {v!r}: must be a file name")
        return None
    try:
        path = _resolve_table_file(v, base)
    except FileNotFoundError as exc:
        detail = str(exc)[str(exc).find("(") + 1:-1] if "(" in str(exc) else ""
        problems.append(f"{pre}.table = {v!r}: file not found" + (f" ({detail})" if detail else ""))
        return None
    meta = _try(problems, read_table_metadata, path)
    if meta is None:
        problems[-1] = f"{pre}.table = {v!r}: {problems[-1]}"
        return None
    missing = [t for t in theories if t not in meta.get("theories", [])]
    if missing:
        problems.append(f"{pre}.table = {v!r}: the table holds theories {meta.get('theories')} "
                        f"but the study needs {missing} (rebuild it with `fastcontact tables "
                        f"build --theories ...`, or use a psd/self-affine surface)")
    for k, val in topts_given.items():
        have = meta.get("options", {}).get(k, {"emt_threshold": 0.5, "anisotropy": 1.0}.get(k))
        if have is not None and not math.isclose(have, val, rel_tol=1e-12):
            problems.append(f"{pre}.table = {v!r}: built with {k} = {have!r} but tables.{k} = {val!r}")
    expected = _expected_surface(pre, v, sd, path, problems)
    bad = None if expected is None else surface_mismatch(meta, expected)
    if bad:
        problems.append(f"{pre}.table = {v!r}: {bad}")
    if len(problems) > n0:
        return None
    return SurfaceSpec(name, "table", path=path, label=label, psd_obj=expected)


def _psd_surface(pre, name, sd, base, problems, label):
    v, conv, n0 = sd["psd"], sd.get("convention"), len(problems)
    if not isinstance(v, str):
        problems.append(f"{pre}.psd = {v!r}: must be a file name")
        return None
    if conv is None:
        problems.append(f"{pre}.convention is missing: psd files need convention = 'persson' "
                        f"or 'surface_topography' (contact.engineering)")
    elif conv not in CONVENTIONS:
        problems.append(f"{pre}.convention = {conv!r}: must be one of {', '.join(CONVENTIONS)}"
                        + did_you_mean(conv, CONVENTIONS))
    p = Path(v).expanduser()
    p = p if p.is_absolute() else base / p
    if not p.is_file():
        problems.append(f"{pre}.psd = {v!r}: file not found ({p})")
    if len(problems) > n0:
        return None
    spec = SurfaceSpec(name, "psd", path=p, convention=conv, label=label)
    if _try(problems, spec.psd) is None:
        problems[-1] = f"{pre}.psd = {v!r}: {problems[-1]}"
        return None
    return spec


def _parse_surface(pre, name, sd, base, theories, topts_given, problems):
    for k in sd:
        if k not in SURFACE_KEYS:
            problems.append(f"{pre}.{k}: unknown key" + did_you_mean(k, list(SURFACE_KEYS)))
    label = sd.get("label")
    if label is not None and not isinstance(label, str):
        problems.append(f"{pre}.label = {label!r}: must be a string")
    if "table" in sd:
        return _table_surface(pre, name, sd, base, theories, topts_given, problems, label)
    has = [s for s in ("psd",) if s in sd] + (["h_rms/hurst/q0/q1"] if any(
        k in sd for k in SELF_AFFINE_KEYS) else [])
    if len(has) != 1:
        problems.append(f"{pre}: give exactly one of table = \"file.parquet\", psd = \"file.csv\" "
                        f"(+ convention) or h_rms, hurst, q0, q1 [, q_roll]"
                        + (f" (got {', '.join(has)})" if has else ""))
        return None
    if "psd" in sd:
        return _psd_surface(pre, name, sd, base, problems, label)
    n0 = len(problems)
    params = _self_affine_params(pre, sd, problems)
    if "convention" in sd:
        problems.append(f"{pre}.convention: only used with psd = ...")
    if len(problems) > n0:
        return None
    spec = SurfaceSpec(name, "self_affine", params=params, label=label)
    if _try(problems, spec.psd) is None:
        problems[-1] = f"{pre}: {problems[-1]}"
        return None
    return spec


def parse_surfaces(sdict, base, theories, topts_given, for_sweep, problems):
    """{name: SurfaceSpec} of ``[surfaces]``; every problem appended to ``problems``."""
    if not sdict and not for_sweep:
        problems.append("[surfaces] is missing: define at least one [surfaces.<name>]")
    surfaces = {}
    for name, sd in sdict.items():
        pre = f"surfaces.{name}"
        if not isinstance(sd, dict):
            problems.append(f"{pre} must be a table: [surfaces.{name}] with table/psd/h_rms... keys")
            continue
        spec = _parse_surface(pre, name, sd, base, theories, topts_given, problems)
        if spec is not None:
            surfaces[name] = spec
    return surfaces
