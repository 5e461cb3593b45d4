"""Compile the engines' kernels ahead of a study: ``fastcontact compile``.

fastcontact's kernels are compiled by numba on first use and cached on disk (beside the
installed package, or in ``$NUMBA_CACHE_DIR``); a later process loads a kernel in ~10 ms. On a
new machine the first call of each path therefore pays its compile once — tens of seconds per
path on 2 cores (measured in ``bench/RESULTS.md``, "Kernel compiling"). :func:`warm` pays it up
front, for the groups of paths a study needs: in a container image or a Dask worker image
before it is deployed, or before timing a study.

Each group runs its engines on a few cases of the embedded ``asphalt_024mm`` tables (``tables``:
a small self-affine surface), through the same public functions a study calls, so the kernels
compiled are exactly those the study will load. Groups run in separate processes (``jobs`` at
a time), whose compiles go to the same cache.

Groups (:data:`GROUPS`): ``tables`` (precompute), ``squeeze`` (squeeze_out by the time
primitive and by per-case quadrature, squeeze_history), ``tire`` (tire_footprint, both
methods), ``seal`` (seal_leak: flat ring and Hertz O-ring, and a study-sized O-ring call with
an outlet pressure that reads the verified O-ring tables), ``viscosity`` (pressure-dependent
viscosity: Barus squeeze_out and tire_footprint, Barus and Roelands seals, and study-sized
O-ring calls of one oil per row and of one Roelands fluid: their table kernels). Each
study-sized call builds its tables (a few seconds). :func:`scene_groups` infers the groups of
a scene.
"""
from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time

__all__ = ["GROUPS", "warm", "warm_group", "scene_groups", "numba_cache_dir"]

#: group name -> what it compiles
GROUPS = {
    "tables": "precompute: effective medium, critical junction and average-theory tables",
    "squeeze": "squeeze_out (time primitive and per-case quadrature), squeeze_history",
    "tire": "tire_footprint (time primitive and per-case quadrature)",
    "seal": "seal_leak: flat ring and Hertz O-ring",
    "viscosity": "alpha_pv / Roelands: squeeze_out, tire_footprint and seal_leak",
}
#: the embedded tables the groups run on, and the cases' common inputs (SI)
_TABLES = "asphalt_024mm"
_E_STAR, _ETA, _R = 13.3e6, 1e-3, 0.01


def _squeeze(T, theory, method):
    import numpy as np
    from .squeeze import squeeze_history, squeeze_out
    p0 = np.array([1e5, 2e5, 4e5])
    kw = dict(E_star=_E_STAR, R=_R, eta=_ETA, theory=theory, method=method)
    squeeze_out(T, p0=p0, **kw)
    squeeze_out(T, p0=p0, u_start=np.array([1e-4, 2e-4, 3e-4]), du=[1e-6],
                times=[1e-3, 1e-2], **kw)
    if method == "fast":
        squeeze_history(T, 2e5, _E_STAR, _R, _ETA, theory=theory, t=np.geomspace(1e-5, 1, 50))


def _tire(T, theory, method, alpha_pv=0.0):
    import numpy as np
    from .squeeze.tire import tire_footprint
    tire_footprint(T, p0=np.array([1e5, 2e5, 4e5]), E_star=_E_STAR, R=_R, eta=_ETA,
                   footprint_length=0.12, speed=np.array([5.0, 20.0, 40.0]), theory=theory,
                   method=method, alpha_pv=alpha_pv)


def _seal(T, **kw):
    import numpy as np
    from .seal.api import seal_leak
    seal_leak(T, p0=2e5, dp=np.array([1e4, 5e4, 1e5]), L=1e-3, L_y=0.1, E_star=_E_STAR,
              eta=_ETA, theory="critical_junction", alpha_cj=0.54, **kw)
    seal_leak(T, profile="hertz", R=2e-3, f_N=np.array([50.0, 100.0]), dp=1e4, L_y=0.1,
              E_star=_E_STAR, eta=_ETA, theory="critical_junction", **kw)


def _seal_tables(T, **kw):
    """Study-sized Hertz O-ring calls (scattered O-rings, and a Δp sweep of one), whose rows
    are read from the verified O-ring tables (built here, a few seconds) instead of solved:
    the table kernels a small call never reaches. ``kw``: the fluid (none: the base fluid
    with an outlet pressure p_b > 0; else ``alpha_pv`` per row or a Roelands law)."""
    import numpy as np
    from .seal.api import seal_leak
    n = 20000
    rng = np.random.default_rng(0)
    base = dict(profile="hertz", R=2e-3, L_y=0.1, E_star=_E_STAR, eta=_ETA,
                theory="critical_junction")
    for f_N, dp in ((rng.uniform(20.0, 200.0, n), rng.uniform(1e3, 5e4, n)),
                    (100.0, np.linspace(1e3, 5e4, n))):
        fluid = {k: (v(n) if callable(v) else v) for k, v in kw.items()} or {"p_b": 0.3 * dp}
        seal_leak(T, f_N=f_N, dp=dp, **base, **fluid)


def warm_group(group):
    """Run group ``group`` (a key of :data:`GROUPS`) in this process; returns its seconds."""
    if group not in GROUPS:
        raise ValueError(f"group = {group!r} is invalid: must be one of {', '.join(GROUPS)}")
    t0 = time.perf_counter()
    if group == "tables":
        from .psd import SelfAffinePSD
        from .tables.build import precompute
        precompute(SelfAffinePSD(h_rms=1e-6, hurst=0.8, q0=1e4, q1=1e6))
        return time.perf_counter() - t0
    from .defaults import load_default_tables
    T = load_default_tables(_TABLES)
    if group == "squeeze":
        for method in ("fast", "quad"):
            _squeeze(T, "emt", method)
    elif group == "tire":
        for method in ("fast", "quad"):
            _tire(T, "emt", method)
    elif group == "seal":
        _seal(T)
        _seal_tables(T)                      # p_b > 0
    else:
        import numpy as np
        from .squeeze import squeeze_out
        for method in ("fast", "quad"):
            # one fluid (the Barus time primitive on the base kernels) and α per case (the
            # per-case Barus kernels)
            for alpha in (1e-7, np.array([1e-7, 2e-7])):
                squeeze_out(T, p0=np.array([1e5, 2e5]), E_star=_E_STAR, R=_R, eta=_ETA,
                            theory="emt", method=method, alpha_pv=alpha)
            for alpha in (1e-7, np.array([1e-7, 2e-7, 1e-7])):
                _tire(T, "emt", method, alpha_pv=alpha)
        _seal(T, alpha_pv=2e-7)
        _seal(T, viscosity="roelands", alpha_pv=2e-7, roelands_z=0.6, roelands_p_r=1.96e8)
        # study-sized O-rings: one oil per row (Barus), one Roelands fluid
        _seal_tables(T, alpha_pv=lambda n: np.linspace(1e-7, 3e-6, n))
        _seal_tables(T, viscosity="roelands", alpha_pv=2e-7, roelands_z=0.6,
                     roelands_p_r=1.96e8)
    return time.perf_counter() - t0


def numba_cache_dir():
    """Where numba keeps the compiled kernels, in words: ``$NUMBA_CACHE_DIR`` where set, else
    the ``__pycache__`` folders of the installed package (numba's default; where the package
    folder is not writable, numba's per-user cache folder)."""
    env = os.environ.get("NUMBA_CACHE_DIR")
    if env:
        return env
    return os.path.join(os.path.dirname(os.path.abspath(__file__)), "*", "__pycache__")


def warm(groups=None, jobs=1, log=None):
    """Compile (or load from the cache) the kernels of ``groups`` (default: every group of
    :data:`GROUPS`), each in a fresh process, ``jobs`` >= 1 at a time; returns {group:
    seconds} (wall time of its process). ``log(message)`` is called as each group ends.
    A group that fails raises RuntimeError with its process's last error line."""
    groups = list(GROUPS) if groups is None else list(dict.fromkeys(groups))
    for g in groups:
        if g not in GROUPS:
            raise ValueError(f"groups = {groups!r} is invalid: {g!r} is not one of "
                             f"{', '.join(GROUPS)}")
    if not (isinstance(jobs, int) and jobs >= 1):
        raise ValueError(f"jobs = {jobs!r} is invalid: must be a whole number >= 1")
    env = dict(os.environ)
    # each process's kernels parallelise over the cores it shares with the others
    env.setdefault("NUMBA_NUM_THREADS", str(max(1, (os.cpu_count() or 1) // min(jobs, len(groups)))))
    pending = list(groups)
    running, done = {}, {}
    while pending or running:
        while pending and len(running) < jobs:
            g = pending.pop(0)
            cmd = [sys.executable, "-c", "from fastcontact.warm import warm_group\n"
                   f"warm_group({g!r})"]
            # stderr to a file, not a pipe: a pipe read only at the end blocks a chatty child
            err = tempfile.TemporaryFile(mode="w+")
            running[g] = (time.perf_counter(), err, subprocess.Popen(
                cmd, env=env, stdout=subprocess.DEVNULL, stderr=err, text=True))
        for g, (t0, err, proc) in list(running.items()):
            if proc.poll() is None:
                continue
            err.seek(0)
            errtext = err.read()
            err.close()
            del running[g]
            if proc.returncode != 0:
                for _g, (_t, _e, p) in running.items():
                    p.kill()
                last = errtext.strip().splitlines()[-1] if errtext.strip() else "no message"
                raise RuntimeError(f"compiling group {g!r} failed (exit {proc.returncode}): "
                                   f"{last}")
            done[g] = time.perf_counter() - t0
            if log:
                log(f"{g}: {done[g]:.1f} s")
        time.sleep(0.05)
    return {g: done[g] for g in groups}


def scene_groups(scene):
    """The groups of :data:`GROUPS` a scene (:class:`~fastcontact.studies.scene.Scene`) needs:
    its study kind's engine, ``viscosity`` where it sets ``alpha_pv`` or the Roelands law,
    ``tables`` where a surface is not a table file (its tables are built) or the study builds
    tables of its own (the asperity levels)."""
    kind = scene.kind
    groups = []
    if kind == "asperity" or any(s.source != "table" for s in scene.surfaces.values()):
        groups.append("tables")
    groups.append({"tire": "tire", "seal": "seal"}.get(kind, "squeeze"))
    given = {**scene.fixed, **scene.axes}
    alpha = given.get("alpha_pv", 0.0)
    if given.get("viscosity", "barus") != "barus" or _nonzero(alpha):
        groups.append("viscosity")
    return groups


def _nonzero(value):
    """True where any element of a scalar or sequence is not zero."""
    import numpy as np
    try:
        return bool(np.any(np.asarray(value, dtype=float) != 0.0))
    except (TypeError, ValueError):
        return True
