"""Issue #6: the command-line interface — example scenes, figures, tables, road databases,
and bad input (exit code 2, one line naming the problem, nothing written)."""
from __future__ import annotations

import io
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import fastcontact
from fastcontact.cli import main
from fastcontact.scene import example_scene_path, list_example_scenes, load_scene

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory, monkeypatch):
    monkeypatch.setenv("FASTCONTACT_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "table_cache"))


def run(*args):
    out, err = io.StringIO(), io.StringIO()
    code = main([str(a) for a in args], out=out, err=err)
    return code, out.getvalue(), err.getvalue()


def assert_png_nontrivial(path):
    """A real plot: big enough, not blank (pixel variance, non-white share)."""
    import matplotlib.image
    path = Path(path)
    assert path.is_file(), path
    assert path.stat().st_size > 20_000, f"{path} is only {path.stat().st_size} bytes"
    img = matplotlib.image.imread(path)
    h, w = img.shape[:2]
    assert h >= 400 and w >= 500, (h, w)
    rgb = img[..., :3].astype(float)
    assert rgb.std() > 0.05, f"{path} looks blank (std {rgb.std():.3g})"
    nonwhite = (rgb.min(axis=2) < 0.9).mean()
    assert 0.02 < nonwhite < 0.9, f"{path}: non-white share {nonwhite:.3g}"
    colored = (rgb.max(axis=2) - rgb.min(axis=2) > 0.2).mean()
    assert colored > 0.002, f"{path}: no coloured curves"


# --------------------------------------------------------------------------- example scenes
EXAMPLES = list_example_scenes()


def test_one_example_per_study_is_shipped():
    kinds = {load_scene(example_scene_path(n), for_sweep=True).kind for n in EXAMPLES}
    assert kinds == {"squeeze", "tire", "seal"}
    assert {"default", "tire_two_asphalts", "road_sweep"} <= set(EXAMPLES)


@pytest.mark.parametrize("name", EXAMPLES)
def test_example_scene_runs_from_cli(name, tmp_path):
    out = tmp_path / "out"
    code, stdout, stderr = run("run", name, "-o", out, "-q")
    assert code == 0, stderr
    df = pd.read_parquet(out / "results.parquet")
    assert len(df) > 0 and (df.error == "").all(), df.error.unique()
    sc = load_scene(example_scene_path(name))
    assert len(df) == len(sc.surfaces) * len(sc.cases())
    rec = json.loads((out / "build_record.json").read_text())
    assert rec["outputs"]["figures"] == sc.figures
    summary = (out / "summary.txt").read_text()
    assert sc.title in summary and "results.parquet" in summary
    for fig in sc.figures:
        assert_png_nontrivial(out / "figures" / f"{sc.kind}_{fig}.png")
        assert f"figure: {out / 'figures' / f'{sc.kind}_{fig}.png'}" in stdout
    assert f"results: {out / 'results.parquet'}" in stdout


def test_default_scene_first_command(tmp_path):
    """The README's first command, through the installed module entry point."""
    out = tmp_path / "out"
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    r = subprocess.run([sys.executable, "-m", "fastcontact.cli", "run", "--default", "-o", str(out)],
                       capture_output=True, text=True, env=env, timeout=600)
    assert r.returncode == 0, r.stderr
    assert f"results: {out / 'results.parquet'}" in r.stdout
    assert r.stdout.count("figure: ") == 2
    rec = json.loads((out / "build_record.json").read_text())
    assert all(t["action"] == "loaded" for t in rec["tables"])       # embedded tables, no build


def test_tire_scene_reproduces_paper_setup(tmp_path):
    code, _, err = run("run", "tire_two_asphalts", "-o", tmp_path / "o", "-q")
    assert code == 0, err
    df = pd.read_parquet(tmp_path / "o" / "results.parquet")
    assert set(df.surface) == {"asphalt_1", "asphalt_2"}
    assert np.allclose(df.p0, 0.2e6) and np.allclose(df.E, 10e6) and np.allclose(df.R, 0.02)
    assert set(df.theory) == {"average"}
    water = df[df.eta == 1e-3].set_index(["surface", "speed"])
    # the smoother road squeezes out ~ a decade slower (paper Sec. 5)
    ratio = water.loc[("asphalt_2", 30.0), "t_star"] / water.loc[("asphalt_1", 30.0), "t_star"]
    assert 3 < ratio < 30
    assert df.squeeze_complete[df.eta == 1e-3].all()


# --------------------------------------------------------------------------- bad input
def _scene_text(**repl):
    text = example_scene_path("squeeze_copper").read_text()
    for a, b in repl.items():
        assert a in text
        text = text.replace(a, b)
    return text          # the table name resolves to the embedded default table


@pytest.mark.parametrize("repl,names", [
    ({'R = "1.5 cm"': 'Radius = "1.5 cm"'}, ["geometry.Radius", "did you mean 'R'", "geometry.R is missing"]),
    ({'eta = "1 mPa s"': 'eta = "1 mPa"'}, ["fluid.eta", "wrong unit 'mPa'"]),
    ({'E = "2.3 MPa"': 'E = "2.3 MPam"'}, ["material.E", "unknown unit 'MPam'"]),
    ({"[surfaces.copper]": '[surfaces.missing]\npsd = "no_such.csv"\nconvention = "persson"\n\n[surfaces.copper]'},
     ["surfaces.missing.psd", "no_such.csv", "not found"]),
    ({'kind = "squeeze"': 'kind = "sqeeze"'}, ["study.kind", "did you mean 'squeeze'"]),
])
def test_bad_scene_exit_2_names_problem_writes_nothing(tmp_path, repl, names):
    scene = tmp_path / "bad.toml"
    scene.write_text(_scene_text(**repl))
    out = tmp_path / "out"
    code, stdout, stderr = run("run", scene, "-o", out)
    assert code == 2
    assert len(stderr.strip().splitlines()) == 1 and "Traceback" not in stderr
    for n in names:
        assert n in stderr, (n, stderr)
    assert not out.exists()
    code, _, stderr2 = run("validate", scene)
    assert code == 2 and names[0] in stderr2


def test_many_problems_reported_together(tmp_path):
    scene = tmp_path / "bad.toml"
    scene.write_text(_scene_text(**{'R = "1.5 cm"': 'R = "1.5 MPa"', 'eta = "1 mPa s"': 'etta = "1 mPa s"',
                                    "[surfaces.copper]": '[surfaces.x]\ntable = "nope.parquet"\n\n[surfaces.copper]'}))
    code, _, err = run("run", scene, "-o", tmp_path / "o")
    assert code == 2
    for n in ("geometry.R", "fluid.etta", "surfaces.x.table", "nope.parquet"):
        assert n in err
    assert "(4 problems)" in err or "(5 problems)" in err


@pytest.mark.parametrize("argv,fragment", [
    (["run", "no_such_scene.toml", "-o", "X"], "no_such_scene.toml"),
    (["run", "-o", "X"], "give a scene"),
    (["frobnicate"], "invalid choice"),
    (["tables", "build", "--hurst", "0.8", "-o", "X.parquet"], "--h-rms"),
    (["tables", "build", "--h-rms", "3 MPa", "--hurst", "0.8", "--q0", "1e4", "--q1", "1e8", "-o", "X.parquet"], "wrong unit"),
    (["tables", "build", "--psd", "f.csv", "-o", "X.parquet"], "--convention"),
    (["tables", "info", "no_such.parquet"], "no_such.parquet"),
    (["roaddb", "generate", "X", "--n", "0", "--seed", "1"], "n_surfaces"),
])
def test_bad_cli_input_one_line_exit_2(argv, fragment, tmp_path):
    argv = [a.replace("X", str(tmp_path / "x")) for a in argv]
    code, out, err = run(*argv)
    assert code == 2
    assert len(err.strip().splitlines()) == 1, err
    assert fragment in err and "Traceback" not in err
    assert not (tmp_path / "x").exists() and not (tmp_path / "x.parquet").exists()


# --------------------------------------------------------------------------- tables
def test_tables_build_and_info(tmp_path):
    t = tmp_path / "t.parquet"
    code, out, err = run("tables", "build", "--h-rms", "10 um", "--hurst", "0.8", "--q0", "1e4",
                         "--q1", "1e8", "--theories", "average,critical_junction", "-o", t)
    assert code == 0, err
    from fastcontact.tables import Tables
    T = Tables.from_parquet(t)
    assert T.theories == ("average", "critical_junction") and T.h_rms == pytest.approx(1e-5)
    code, out, err = run("tables", "info", t)
    assert code == 0, err
    for frag in ("surface: SelfAffinePSD(h_rms=1e-05", "theories: average, critical_junction",
                 "options: ", "a_perc = 0.5", "grid: p/E*", "interpolation errors", "build time:",
                 f"fastcontact version: {fastcontact.__version__}", "references:", "Lorenz",
                 "surface hash:"):
        assert frag in out, frag
    code, out, _ = run("tables", "info", "--json", t)
    assert json.loads(out)["theories"] == ["average", "critical_junction"]


def test_tables_build_from_psd_file(tmp_path):
    from fastcontact.psd import SelfAffinePSD
    from fastcontact.topography import write_psd
    psd = SelfAffinePSD(10e-6, 0.8, 1e4, 1e8, q_roll=3e4)
    write_psd(psd, tmp_path / "p.csv", "surface_topography")
    code, out, err = run("tables", "build", "--psd", tmp_path / "p.csv", "--convention",
                         "surface_topography", "--theories", "average", "-o", tmp_path / "t.parquet")
    assert code == 0, err
    from fastcontact.tables import Tables
    T = Tables.from_parquet(tmp_path / "t.parquet")
    assert T.h_rms == pytest.approx(10e-6, rel=1e-9) and T.theories == ("average",)


def test_embedded_table_info():
    code, out, err = run("tables", "info", ROOT / "fastcontact" / "data" / "asphalt_072mm.parquet")
    assert code == 0 and "h_rms = 0.00072 m" in out


# --------------------------------------------------------------------------- roaddb, scenes
def test_roaddb_cli(tmp_path):
    code, out, err = run("roaddb", "generate", tmp_path / "db", "--n", "5", "--seed", "2")
    assert code == 0, err
    code, out, err = run("roaddb", "info", tmp_path / "db")
    assert code == 0 and "5 surfaces" in out


def test_scenes_list_and_show():
    code, out, _ = run("scenes")
    assert code == 0 and all(n in out for n in EXAMPLES)
    code, out, _ = run("scenes", "tire_two_asphalts")
    assert code == 0 and 'kind = "tire"' in out


# --------------------------------------------------------------------------- figures
def test_figures_command_makes_every_paper_figure(tmp_path):
    code, out, err = run("figures", "-o", tmp_path)
    assert code == 0, err
    pngs = sorted(tmp_path.glob("*.png"))
    assert {"reduced_u_of_t.png", "reduced_tstar.png", "tire_u_of_t.png", "tire_du_of_t.png"} <= {p.name for p in pngs}
    assert len(pngs) >= 6                       # + the squeeze and seal modules' figures
    for p in pngs:
        assert_png_nontrivial(p)


def test_figures_missing_module_fails_loudly(monkeypatch, tmp_path):
    import fastcontact.cli as cli
    monkeypatch.setattr(cli, "FIGURE_MODULES", (cli.FIGURE_MODULES[0], ("fastcontact.figures.nope_figures", "make")))
    with pytest.raises(SystemExit) as exc:
        run("figures", "-o", tmp_path)
    assert "fastcontact.figures.nope_figures is missing" in str(exc.value.code)
    assert not list(tmp_path.glob("*.png"))          # fails before making anything


def test_tables_defaults_writes_both_copies_in_a_checkout_and_refuses_an_install(monkeypatch):
    """Without -o it writes the package's copy and tables/ of a source checkout (the freshness
    test compares the package's copy); an installed package is refused, nothing is built."""
    from fastcontact.tables import defaults
    assert [str(d) for d in defaults.default_outdirs()] == [
        str(ROOT / "fastcontact" / "data"), str(ROOT / "tables")]
    monkeypatch.setattr(defaults, "SOURCE_CHECKOUT", None)
    code, out, err = run("tables", "defaults")
    assert code != 0 and "not in a source checkout" in err and out == ""
