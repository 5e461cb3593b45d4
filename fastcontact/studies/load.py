"""Reading and validating a scene file: :func:`load_scene` reports every problem at once.

A scene is plain data, parsed with :mod:`tomllib` (``tomli`` on Python 3.10); nothing in it is
evaluated. One parser per section; the study kind's own requirements come from
:data:`fastcontact.studies.kinds.KINDS`.
"""
from __future__ import annotations

import fnmatch
import json
import math
from pathlib import Path

import numpy as np

try:
    import tomllib
except ModuleNotFoundError:   # Python 3.10
    import tomli as tomllib

from .._core.vocab import THEORIES
from ..validation.calibration import Calibration
from .examples import example_scene_path
from .kinds import KINDS
from .scene import Scene, SceneError, count_cases
from .schema import (AXIS_KEYS, MAX_CASES, RANGE_KEYS, SCHEMA, STUDY_KINDS, TOP_KEYS, Key,
                     did_you_mean, parse_scalar as _parse_scalar, try_parse as _try)
from .surfaces import parse_surfaces

__all__ = ["load_scene", "available_figures"]

_SECTIONS = ("study", "material", "fluid", "geometry", "tables", "outputs", "sweep", "surfaces")


def available_figures(kind) -> list:
    """Figure names a study of ``kind`` may request."""
    return list(KINDS[kind].figures)


# =========================================================================== values
def _parse_range(key, value, spec, problems, max_cases):
    """SI float64 array of a range table ``{start, stop, num, log}`` (``num`` checked against
    the study limit before anything is allocated)."""
    unknown = [k for k in value if k not in RANGE_KEYS]
    for k in unknown:
        problems.append(f"{key}.{k}: unknown key in a range table" + did_you_mean(k, RANGE_KEYS))
    missing = [k for k in ("start", "stop", "num") if k not in value]
    for k in missing:
        problems.append(f"{key}: range table needs '{k}' (keys: start, stop, num, log)")
    if missing:
        return None
    n0 = len(problems)
    a = _try(problems, _parse_scalar, f"{key}.start", value["start"], spec)
    b = _try(problems, _parse_scalar, f"{key}.stop", value["stop"], spec)
    num, log = value["num"], value.get("log", False)
    if isinstance(num, bool) or not isinstance(num, int) or num < 1:
        problems.append(f"{key}.num = {num!r}: must be an integer >= 1")
    elif num > max_cases:
        problems.append(f"{key}.num = {num}: more values than the study limit max_cases = "
                        f"{max_cases:g} (raise it with [outputs] max_cases or --max-cases)")
    if not isinstance(log, bool):
        problems.append(f"{key}.log = {log!r}: must be true or false")
    if len(problems) > n0 or unknown:
        return None
    if log:
        if a <= 0 or b <= 0:
            problems.append(f"{key}: a log range needs start and stop > 0")
            return None
        return np.geomspace(a, b, num)
    return np.linspace(a, b, num)


def _parse_axis(key, value, spec, problems, max_cases):
    """List of SI floats of an axis value (scalar, list or range table)."""
    if isinstance(value, dict):
        return _parse_range(key, value, spec, problems, max_cases)
    if isinstance(value, list):
        if not value:
            problems.append(f"{key} = []: an axis needs at least one value")
            return None
        out = [_try(problems, _parse_scalar, f"{key}[{i}]", v, spec) for i, v in enumerate(value)]
        return None if any(x is None for x in out) else out
    x = _try(problems, _parse_scalar, key, value, spec)
    return None if x is None else [x]


def _parse_list_num(key, value, spec, problems):
    vals = value if isinstance(value, list) else [value]
    out = [_try(problems, _parse_scalar, f"{key}[{i}]" if isinstance(value, list) else key, v, spec)
           for i, v in enumerate(vals)]
    return None if any(x is None for x in out) else tuple(out)


def _parse_theories(key, v, problems):
    vals = v if isinstance(v, list) else [v]
    ok = bool(vals)
    if not vals:
        problems.append(f"{key} = []: name at least one theory")
    for t in vals:
        if not isinstance(t, str) or t not in THEORIES:
            problems.append(f"{key} = {t!r}: unknown theory" + did_you_mean(t, THEORIES))
            ok = False
    return list(dict.fromkeys(vals)) if ok else None


def _parse_profile(key, v, problems):
    if isinstance(v, str):
        if v in ("uniform", "parabolic"):
            return v
        problems.append(f"{key} = {v!r}: must be 'uniform', 'parabolic' or a list of relative "
                        f"pressures" + did_you_mean(v, ("uniform", "parabolic")))
    elif isinstance(v, list) and len(v) >= 2:
        vals = _parse_list_num(key, v, Key("num", lo=0), problems)
        if vals is not None and sum(vals) <= 0:
            problems.append(f"{key}: the relative pressures must not all be 0")
        elif vals is not None:
            return tuple(vals)
    else:
        problems.append(f"{key} = {v!r}: must be 'uniform', 'parabolic' or a list of >= 2 "
                        f"relative pressures along the footprint")
    return None


def _parse_value(key, v, spec, problems, max_cases):
    """(is_axis, parsed value or None) of one scene value."""
    if spec.kind == "num":
        if spec.axis:
            return True, _parse_axis(key, v, spec, problems, max_cases)
        return False, _try(problems, _parse_scalar, key, v, spec)
    if spec.kind == "theory":
        return True, _parse_theories(key, v, problems)
    if spec.kind == "choice":
        if isinstance(v, str) and v in spec.choices:
            return False, v
        problems.append(f"{key} = {v!r}: must be one of {', '.join(spec.choices)}"
                        + (did_you_mean(v, spec.choices) if isinstance(v, str) else ""))
        return False, None
    if spec.kind == "str":
        if isinstance(v, str):
            return False, v
        problems.append(f"{key} = {v!r}: must be a string")
        return False, None
    if spec.kind == "list_num":
        return False, _parse_list_num(key, v, spec, problems)
    if spec.kind == "strlist":
        vals = v if isinstance(v, list) else [v]
        if all(isinstance(x, str) for x in vals):
            return False, list(vals)
        problems.append(f"{key} = {v!r}: must be a list of strings")
        return False, None
    return False, _parse_profile(key, v, problems)        # "profile"


# =========================================================================== sections
def _read_source(scene, base_dir):
    """(data, text, source, base folder) of a scene path, example name or dict."""
    if isinstance(scene, dict):
        return (scene, json.dumps(scene, sort_keys=True, default=str), "<dict>",
                Path(base_dir or ".").resolve())
    path = Path(scene)
    if not path.is_file():
        try:
            path = example_scene_path(scene)
        except FileNotFoundError as exc:
            hint = str(exc)[str(exc).find(" (did"):] if "(did" in str(exc) else ""
            raise SceneError(scene, [f"scene file {str(scene)!r} does not exist{hint}"]) from None
    source = str(path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise SceneError(source, [f"cannot read scene file: {exc}"]) from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(source, [f"not valid TOML: {exc}"]) from None
    return data, text, source, Path(base_dir).resolve() if base_dir else path.resolve().parent


def _sections(data, problems):
    for k in data:
        if k not in TOP_KEYS:
            problems.append(f"{k}: unknown top-level key" + did_you_mean(k, TOP_KEYS))
    for k in ("title", "description"):
        if k in data and not isinstance(data[k], str):
            problems.append(f"{k} = {data[k]!r}: must be a string")
    sections = {}
    for sec in _SECTIONS:
        v = data.get(sec, {})
        if not isinstance(v, dict):
            problems.append(f"[{sec}] must be a table (section), got {type(v).__name__}")
            v = {}
        sections[sec] = v
    return sections


def _study_kind(study, problems):
    kind = study.get("kind")
    if kind is None:
        problems.append(f"study.kind is missing: one of {', '.join(STUDY_KINDS)}")
    elif kind not in STUDY_KINDS:
        problems.append(f"study.kind = {kind!r}: unknown study kind" + did_you_mean(kind, STUDY_KINDS))
        kind = None
    return kind


def _max_cases(sections, override, problems):
    if override is not None:
        return int(override)
    v = sections["outputs"].get("max_cases")
    if v is None:
        return MAX_CASES
    x = _try(problems, _parse_scalar, "outputs.max_cases", v, SCHEMA["outputs"]["max_cases"])
    return MAX_CASES if x is None else int(x)


def _parse_keys(sections, kind, problems, max_cases):
    """(axes, fixed, given) of every schema section; unknown and unused keys reported."""
    axes, fixed, given = {}, {}, {}
    for sec, keys in SCHEMA.items():
        for k, v in sections[sec].items():
            key, spec = f"{sec}.{k}", keys.get(k)
            if spec is None:
                problems.append(f"{key}: unknown key" + did_you_mean(k, list(keys)))
                continue
            if kind is not None and kind not in spec.studies:
                problems.append(f"{key}: not used by a {kind!r} study (used by: "
                                f"{', '.join(spec.studies)})")
                continue
            given[(sec, k)] = v
            if key in ("study.kind", "outputs.max_cases"):
                continue
            is_axis, val = _parse_value(key, v, spec, problems, max_cases)
            if val is not None:
                (axes if is_axis else fixed)[f"{sec}.{k}" if spec.kind == "strlist" else k] = val
    return axes, fixed, given


def _infer(kind, axes, fixed, given, problems):
    """Defaults and requirements common to every study, then the kind's own."""
    defaults = KINDS[kind].defaults
    hertz = kind == "seal" and fixed.get("profile") == "hertz"
    if "p0" not in axes and ("study", "p0") not in given and not hertz:
        problems.append("study.p0 is missing: the nominal pressure, e.g. p0 = \"0.2 MPa\"")
    if "theory" not in axes and ("study", "theory") not in given:
        axes["theory"] = [defaults["theory"]]
    for k in ("ratios", "du", "times", "pressure_profile", "pressure_model", "du_complete",
              "profile"):
        if k in defaults and k not in fixed and ("study", k) not in given:
            fixed[k] = defaults[k]
    KINDS[kind].infer(axes, fixed, given, problems)


def _check_material(given, problems):
    if ("fluid", "eta") not in given:
        problems.append("fluid.eta is missing: the viscosity, e.g. eta = \"1 mPa s\"")
    mat = {k for (s, k) in given if s == "material"}
    if "E_star" in mat:
        for k in ("E", "nu", "E2", "nu2"):
            if k in mat:
                problems.append(f"material.{k}: give either E_star or E and nu, not both")
        return
    for k in ("E", "nu"):
        if k not in mat:
            problems.append(f"material.{k} is missing: give E and nu (E* = E/(1-nu^2)) or E_star")
    if ("E2" in mat) != ("nu2" in mat):
        problems.append("material.E2/nu2: give both the second solid's E2 and nu2, or neither")


def _calibration_options(kind, fixed, given_opts, base, problems):
    """``tables.calibration``: the calibration file's constants merged into ``given_opts``.

    The file (relative to the scene) is read by
    :meth:`fastcontact.validation.Calibration.from_toml` (plain TOML, no BEM extra needed);
    a constant also given in ``[tables]`` must agree.
    ``emt_threshold`` is added only when it differs from 0.5 (default tables, cache keys).
    """
    v = fixed.pop("calibration", None)
    if v is None:
        return
    p = Path(v).expanduser()
    p = p if p.is_absolute() else base / p
    if not p.is_file():
        problems.append(f"tables.calibration = {v!r}: file not found ({p})")
        return
    try:
        cal = Calibration.from_toml(p)
    except Exception as exc:  # noqa: BLE001 - TOML, key and range errors alike
        problems.append(f"tables.calibration = {v!r}: not a calibration file "
                        f"({type(exc).__name__}: {exc})")
        return
    for k in ("gamma", "a_perc", "alpha_cj", "emt_threshold"):
        val = float(getattr(cal, k))
        if k in given_opts and not math.isclose(float(given_opts[k]), val, rel_tol=1e-12):
            problems.append(f"tables.{k} = {given_opts[k]!r}: conflicts with tables.calibration "
                            f"= {v!r}, which sets {k} = {val!r} (give one or the other)")
        elif k == "alpha_cj" and kind == "seal":
            if val != 1.0:
                problems.append(f"tables.calibration = {v!r} sets alpha_cj = {val!r}: for a seal "
                                f"study give it as study.alpha_cj = {val!r} (tables keep α_cj = 1)")
        elif k != "emt_threshold" or val != 0.5:
            given_opts[k] = val


def _table_options(kind, fixed, given, base, problems):
    """(options with defaults, options given, cache folder) of ``[tables]``."""
    given_opts = {k: fixed.pop(k) for k in ("gamma", "a_perc", "alpha_cj") if k in fixed}
    aniso = fixed.pop("anisotropy", 1.0)
    if aniso is not None and aniso != 1.0:                  # issue 14: anisotropic tables
        given_opts["anisotropy"] = aniso
    _calibration_options(kind, fixed, given_opts, base, problems)
    if kind == "seal" and ("tables", "alpha_cj") in given:
        problems.append("tables.alpha_cj: for a seal study give the junction factor as "
                        "study.alpha_cj (it rescales σ_cj by α_cj³ on tables built with α_cj = 1)")
    opts = {"gamma": 1.0, "a_perc": 0.5, "alpha_cj": 1.0, **given_opts}
    cache_dir = fixed.pop("cache_dir", None)
    if cache_dir is not None:
        cache_dir = str(base / Path(cache_dir).expanduser())
    fixed.pop("name", None)
    return opts, given_opts, cache_dir


def _outputs(kind, fixed, problems):
    """(columns, figures) requested, checked against what the kind offers."""
    avail = KINDS[kind].columns(fixed)
    want = fixed.pop("outputs.columns", None)
    columns = [] if want is not None else list(avail)
    for w in want or ():
        hit = [c for c in avail if fnmatch.fnmatchcase(c, w)]
        if not hit:
            problems.append(f"outputs.columns: unknown column {w!r} for a {kind!r} study"
                            + did_you_mean(w, avail))
        columns.extend(c for c in hit if c not in columns)
    figures, favail = [], KINDS[kind].figures
    for f in fixed.pop("outputs.figures", None) or []:
        if f not in favail:
            problems.append(f"outputs.figures: unknown figure {f!r} for a {kind!r} study"
                            + did_you_mean(f, favail))
        elif f not in figures:
            figures.append(f)
    return columns, figures


def _check_size(axes, combine, n_surfaces, max_cases, problems):
    """The study's size, counted (nothing allocated), against ``max_cases``."""
    if combine == "zip":
        lens = {k: len(v) for k, v in axes.items() if len(v) > 1}
        if len(set(lens.values())) > 1:
            problems.append(f"sweep.combine = 'zip': the list axes have different lengths {lens}")
            return
    n = count_cases(axes, combine) * max(n_surfaces, 1)
    if n > max_cases:
        problems.append(f"the study has {n:,} cases ({n_surfaces} surface(s) x "
                        f"{count_cases(axes, combine):,}), more than max_cases = {max_cases:,}; "
                        f"raise the limit with [outputs] max_cases or --max-cases")


# =========================================================================== entry
def load_scene(scene, *, for_sweep=False, base_dir=None, max_cases=None) -> Scene:
    """Parse and validate a scene; return a :class:`Scene` or raise :class:`SceneError`.

    Parameters
    ----------
    scene : path-like, str or dict
        A TOML file, the name of a shipped example scene, or the parsed TOML as a dict.
    for_sweep : bool
        The surfaces come from a road database, so ``[surfaces]`` is optional.
    base_dir : path-like, optional
        Folder that relative file names are resolved against (default: the scene's folder).
    max_cases : int, optional
        Largest study allowed (cases x surfaces), overriding ``[outputs] max_cases``
        (default :data:`fastcontact.studies.schema.MAX_CASES` = 2e7). Checked by counting,
        before anything is allocated.

    Raises
    ------
    SceneError
        Listing every problem (unknown keys with did-you-mean, wrong types, units and ranges,
        missing or unusable files, a table file of another surface, a study too large).

    Notes
    -----
    Sections: ``[study]`` (``kind`` = squeeze | tire | seal, ``theory`` (default
    ``"critical_junction"``, :data:`fastcontact._core.vocab.DEFAULT_THEORY`), ``p0`` and the
    kind's parameters), ``[surfaces.<name>]`` (``table`` = a table file or embedded default,
    optionally with the surface's self-affine parameters to check it; ``psd`` = file +
    ``convention``; or ``h_rms``, ``hurst``, ``q0``, ``q1`` [, ``q_roll``]), ``[material]``
    (``E_star``, or ``E``, ``nu`` [, ``E2``, ``nu2``]), ``[fluid]`` (``eta``, ``rho``),
    ``[geometry]`` (``R``, ``L``, ``L_y``), ``[tables]`` (``gamma``, ``a_perc``, ``alpha_cj``,
    ``cache_dir``, ``calibration`` = a calibration TOML file), ``[outputs]`` (``columns``,
    ``figures``, ``max_cases``), ``[sweep]`` (``combine`` = product | zip). Numbers are SI or
    strings with units (``"0.2 MPa"``). Every axis key may be a scalar, a list or a range
    ``{start, stop, num, log}``.
    """
    data, text, source, base = _read_source(scene, base_dir)
    problems = []
    sections = _sections(data, problems)
    kind = _study_kind(sections["study"], problems)
    limit = _max_cases(sections, max_cases, problems)
    axes, fixed, given = _parse_keys(sections, kind, problems, limit)
    if kind is not None:
        _infer(kind, axes, fixed, given, problems)
    _check_material(given, problems)
    topts, topts_given, cache_dir = _table_options(kind, fixed, given, base, problems)
    theories = tuple(t for t in THEORIES if t in axes.get("theory", ()))
    surfaces = parse_surfaces(sections["surfaces"], base, theories, topts_given, for_sweep, problems)
    columns, figures = _outputs(kind, fixed, problems) if kind is not None else ([], [])
    combine = fixed.pop("combine", "product")
    _check_size(axes, combine, len(sections["surfaces"]), limit, problems)
    if problems:
        raise SceneError(source, problems)
    axes = {k: axes[k] for k in AXIS_KEYS if k in axes}
    title = data.get("title") or (Path(source).stem if source != "<dict>" else "scene")
    return Scene(source=source, base_dir=base, text=text, data=data, title=title, kind=kind,
                 surfaces=surfaces, axes=axes, fixed=fixed, table_options=topts,
                 table_options_given=topts_given, cache_dir=cache_dir, columns=columns,
                 figures=figures, combine=combine, max_cases=limit)
