"""A warm ``fastcontact run --default`` stays quick (issue 12 point 5): nothing heavy or
optional is imported, the run figures need no mathtext, squeeze time primitives are kept in
the cache folder (and said so), and the fast exit of the command line keeps profilers
working."""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]

#: never imported by a warm default run (scipy.linalg is numba's own import)
HEAVY = ("scipy.special", "scipy.integrate", "scipy.optimize", "scipy.interpolate",
         "SurfaceTopography", "ContactMechanics", "dask", "distributed", "pint",
         "matplotlib.pyplot", "tqdm", "fastcontact.seal", "fastcontact.surface.topography",
         "fastcontact.validation.bem")


def _env(tmp_path):
    return dict(os.environ, FASTCONTACT_CACHE_DIR=str(tmp_path / "cache"),
                PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))


def test_default_run_imports_nothing_heavy(tmp_path):
    code = ("import json, sys\n"
            "from fastcontact.cli import main\n"
            f"rc = main(['run', '--default', '-o', {str(tmp_path / 'out')!r}, '-q'])\n"
            f"print(json.dumps([rc, [m for m in {HEAVY!r} if m in sys.modules]]))\n")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                       env=_env(tmp_path), timeout=600)
    assert r.returncode == 0, r.stderr
    rc, loaded = json.loads(r.stdout.strip().splitlines()[-1])
    assert rc == 0 and loaded == []
    assert (tmp_path / "out" / "figures" / "squeeze_u_of_t.png").is_file()


def test_run_figures_parse_no_mathtext(tmp_path, monkeypatch):
    import matplotlib.mathtext as mt

    import fastcontact.figures.scene as fs
    from fastcontact.studies.examples import example_scene_path
    from fastcontact.studies.load import load_scene
    from fastcontact.studies.run import run_scene
    parsed = []
    orig = mt.MathTextParser.parse

    def parse(self, s, *a, **k):
        parsed.append(s)
        return orig(self, s, *a, **k)
    monkeypatch.setattr(mt.MathTextParser, "parse", parse)
    monkeypatch.setenv("FASTCONTACT_CACHE_DIR", str(tmp_path / "cache"))
    res = run_scene(load_scene(example_scene_path("default")), tmp_path / "o",
                    make_figures=fs.make_scene_figure)
    assert len(res.figures) == 2 and all(p.is_file() for p in res.figures)
    assert parsed == []


def test_plain_log_labels_match_matplotlib():
    """The plain-text log labels label exactly the ticks matplotlib labels, with the same
    value (matplotlib's mathtext label is the reference)."""
    import re

    from matplotlib.ticker import LogFormatterSciNotation

    from fastcontact.figures.canvas import PlainLogFormatter
    sup = str.maketrans("⁰¹²³⁴⁵⁶⁷⁸⁹⁻−", "0123456789--")
    for only_base in (True, False):
        ref, ours = LogFormatterSciNotation(10.0, only_base), PlainLogFormatter(10.0, only_base)
        for x in (1e-12, 2e-7, 5e-3, 1e-3, 0.3, 1.0, 3.0, 10.0, 7e4, 1e5):
            a, b = ref(x), ours(x)
            assert (a == "") == (b == ""), (x, a, b)
            assert "$" not in b
            if b:
                m = re.fullmatch(r"(?:(\d+)×)?10([⁰¹²³⁴⁵⁶⁷⁸⁹⁻]+)", b)
                assert m, b
                val = float(m.group(1) or 1) * 10.0 ** int(m.group(2).translate(sup))
                assert val == pytest.approx(x, rel=1e-12), (x, b)
    assert PlainLogFormatter(10.0)(1e-3) == "10⁻³"
    assert PlainLogFormatter(10.0, labelOnlyBase=False)(2e-3) == "2×10⁻³"


def test_squeeze_primitive_cached_and_reused(tmp_path):
    """A study on the fast path builds the squeeze time primitive once, writes it into the
    cache folder and says where; a later run (another process) reads it."""
    scene = tmp_path / "big.toml"
    scene.write_text('title = "big"\n[study]\nkind = "squeeze"\ntheory = "emt"\n'
                     'p0 = { start = "0.05 MPa", stop = "1 MPa", num = 2500, log = true }\n'
                     '[surfaces.road]\ntable = "asphalt_024mm"\n'
                     '[material]\nE = "10 MPa"\nnu = 0.5\n[fluid]\neta = "1 mPa s"\n'
                     '[geometry]\nR = "2 cm"\n[outputs]\nfigures = []\n')
    cmd = [sys.executable, "-m", "fastcontact", "run", str(scene), "-o"]
    r1 = subprocess.run(cmd + [str(tmp_path / "o1")], capture_output=True, text=True,
                        env=_env(tmp_path), timeout=600)
    assert r1.returncode == 0, r1.stderr
    folder = tmp_path / "cache" / "squeeze_primitives"
    files = sorted(folder.glob("squeeze_primitive_emt_*.parquet"))
    assert len(files) == 1
    assert f"squeeze time primitive cached in {files[0]}" in r1.stderr
    stamp = files[0].stat().st_mtime_ns
    r2 = subprocess.run(cmd + [str(tmp_path / "o2")], capture_output=True, text=True,
                        env=_env(tmp_path), timeout=600)
    assert r2.returncode == 0, r2.stderr
    assert "squeeze time primitive cached" not in r2.stderr
    assert files[0].stat().st_mtime_ns == stamp                   # read, not rewritten
    import pandas as pd
    a, b = (pd.read_parquet(tmp_path / o / "results.parquet") for o in ("o1", "o2"))
    assert len(a) == 2500
    np.testing.assert_array_equal(a["t_star"].to_numpy(), b["t_star"].to_numpy())


def test_command_line_exit_keeps_a_profile(tmp_path):
    """The command line leaves without the interpreter's teardown, but not under a profiler:
    ``python -m cProfile -o F -m fastcontact run ...`` still writes F."""
    prof = tmp_path / "run.prof"
    r = subprocess.run([sys.executable, "-m", "cProfile", "-o", str(prof), "-m", "fastcontact",
                        "run", "--default", "-o", str(tmp_path / "out"), "-q", "--no-figures"],
                       capture_output=True, text=True, env=_env(tmp_path), timeout=600)
    assert r.returncode == 0, r.stderr
    assert prof.is_file() and prof.stat().st_size > 0
    assert "results: " in r.stdout


def test_batched_curves_match_the_history_engine():
    """The run figures' batched ū(t) curves (one quadrature call per surface on a shared log
    grid) equal ū(t) of squeeze_history (the time-primitive path) case by case; a case the
    engine does not run gets an empty curve and does not sink the others."""
    from fastcontact.figures.tire_figures import tire_curves
    from fastcontact.squeeze import squeeze_history
    from fastcontact.tables.defaults import load_default_tables
    T = load_default_tables("asphalt_024mm")
    E, R, eta = 13.3e6, 0.02, 1e-3
    p0 = [1e5, 5e5, 2e5]
    cs = tire_curves(T, p0=p0, E_star=[E] * 3, R=[R] * 3, eta=[eta] * 3,
                     theory="critical_junction", u_start=[1e-2, 1e-2, 1e-9], n=40)
    for c, p in zip(cs[:2], p0[:2]):
        assert c["t"].size >= 38 and np.all(np.diff(c["t"]) > 0)
        h = squeeze_history(T, p, E, R, eta, "critical_junction", t=c["t"], u_start=1e-2)
        np.testing.assert_allclose(c["u"], h["u"].to_numpy(), rtol=1e-6)
        stefan = 1e-2 / np.sqrt(1.0 + 4.0 * 1e-4 * p * c["t"] / (3.0 * eta * R ** 2))
        np.testing.assert_allclose(c["flat"], stefan, rtol=1e-12)
        assert c["u"][-1] == pytest.approx(c["u_inf"], rel=1e-3)     # reaches equilibrium
    assert cs[2]["t"].size == 0 and cs[2]["u"].size == 0
