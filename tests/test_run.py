"""Runs of scenes: bounded studies, streamed results with units, complete output folders,
table files checked against the scene's surface, the CLI's one-line errors (issues 12, 15)."""
from __future__ import annotations

import io
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

from fastcontact.cli import main
from fastcontact.studies.load import load_scene
from fastcontact.studies.run import run_scene
from fastcontact.studies.scene import SceneError

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory, monkeypatch):
    monkeypatch.setenv("FASTCONTACT_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "table_cache"))


def cli(*args):
    out, err = io.StringIO(), io.StringIO()
    code = main([str(a) for a in args], out=out, err=err)
    return code, out.getvalue(), err.getvalue()


def scene(**over):
    sc = {"title": "t",
          "study": {"kind": "squeeze", "theory": "average", "p0": ["0.1 MPa", "0.3 MPa"],
                    "ratios": [1.1, 1.01], "du": ["1 um"]},
          "surfaces": {"a": {"table": "asphalt_024mm"}},
          "material": {"E": "10 MPa", "nu": 0.5}, "fluid": {"eta": ["1 mPa s", "3 mPa s"]},
          "geometry": {"R": "2 cm"}}
    sc.update(over)
    return sc


# --------------------------------------------------------------------------- bounded studies
def test_huge_axis_refused_before_allocating(tmp_path):
    sc = scene()
    sc["study"]["p0"] = {"start": "0.1 MPa", "stop": "1 MPa", "num": 10**9, "log": True}
    with pytest.raises(SceneError, match=r"study\.p0\.num = 1000000000.*max_cases"):
        load_scene(sc)


def test_product_of_axes_counted_against_limit():
    sc = scene()
    sc["study"]["p0"] = {"start": "0.1 MPa", "stop": "1 MPa", "num": 5000}
    sc["fluid"]["eta"] = {"start": "1 mPa s", "stop": "1 Pa s", "num": 5000}
    with pytest.raises(SceneError, match=r"25,000,000 cases.*max_cases = 20,000,000"):
        load_scene(sc)
    s = load_scene(sc, max_cases=3 * 10**7)              # an explicit limit raises it
    assert s.n_cases == 25_000_000 and s.max_cases == 3 * 10**7
    with pytest.raises(SceneError, match=r"4 cases .*max_cases = 3;"):
        load_scene(scene(outputs={"max_cases": 3}))
    assert load_scene(scene(outputs={"max_cases": 4})).n_cases == 4


def test_validate_refuses_huge_axis_from_cli(tmp_path):
    text = (ROOT / "fastcontact" / "scenes" / "default.toml").read_text()
    big = tmp_path / "big.toml"
    big.write_text(text.replace("num = 4", "num = 1000000000"))
    code, _, err = cli("validate", big)
    assert code == 2 and "max_cases" in err and len(err.strip().splitlines()) == 1
    code, out, err = cli("validate", big, "--max-cases", "100")
    assert code == 2 and "max_cases = 100" in err


# --------------------------------------------------------------------------- streaming
def test_blocks_give_the_same_rows_as_one_block(tmp_path):
    s = load_scene(scene())
    one = run_scene(s, tmp_path / "one")
    many = run_scene(s, tmp_path / "many", chunk_size=3)
    a = pd.read_parquet(one.results_path)
    b = pd.read_parquet(many.results_path)
    pd.testing.assert_frame_equal(a, b)
    assert list(a.case_id) == [0, 1, 2, 3]
    assert one.record["rows"] == many.record["rows"] == 4


def test_every_column_carries_its_unit(tmp_path):
    res = run_scene(load_scene(scene()), tmp_path / "o")
    schema = pq.read_schema(res.results_path)
    units = {f.name: (f.metadata or {}).get(b"unit", b"?").decode() for f in schema}
    assert units["p0"] == "Pa" and units["eta"] == "Pa s" and units["R"] == "m"
    assert units["u_inf"] == "m" and units["t_star"] == "s" and units["t_ratio_1.1"] == "s"
    assert units["t_du_1e-06"] == "s" and units["trapped"] == "bool" and units["nu"] == "1"
    assert set(units) == set(schema.names)
    meta = json.loads(schema.metadata[b"fastcontact"])
    assert meta["units"] == units
    assert res.results.attrs["units"]["u_inf"] == "m"
    summary = res.summary_path.read_text()
    assert "u_inf" in summary and "[m]" in summary and "[s]" in summary


# --------------------------------------------------------------------------- output folder
def test_failed_run_leaves_no_folder(tmp_path):
    s = load_scene(scene(outputs={"figures": ["t_star"]}))

    def broken(*args):
        raise RuntimeError("figure maker failed")

    with pytest.raises(RuntimeError):
        run_scene(s, tmp_path / "out", make_figures=broken)
    assert not (tmp_path / "out").exists()
    assert not [p for p in tmp_path.iterdir()]              # no temporary folder left


def test_output_into_a_file_is_refused(tmp_path):
    f = tmp_path / "file"
    f.write_text("x")
    code, out, err = cli("run", "--default", "-o", f)
    assert code == 2 and "is a file" in err and len(err.strip().splitlines()) == 1
    assert f.read_text() == "x"


# --------------------------------------------------------------------------- table checks
def test_table_of_another_surface_is_refused():
    sc = scene()
    sc["surfaces"] = {"a": {"table": "asphalt_072mm", "h_rms": "0.24 mm", "hurst": 0.8,
                            "q0": "314.159 1/m", "q1": "1e6 1/m", "q_roll": "2094.4 1/m"}}
    with pytest.raises(SceneError) as exc:
        load_scene(sc)
    msg = str(exc.value)
    assert "different surface" in msg and "h_rms = 0.00072 m" in msg and "h_rms = 0.00024 m" in msg


def test_table_described_correctly_is_accepted():
    from fastcontact.tables.defaults import DEFAULT_SURFACES
    d = DEFAULT_SURFACES["asphalt_024mm"]
    sc = scene()
    sc["surfaces"] = {"a": {"table": "asphalt_024mm", "h_rms": d["h_rms"], "hurst": d["hurst"],
                            "q0": d["q0"], "q1": d["q1"], "q_roll": d["q_roll"]}}
    assert load_scene(sc).surfaces["a"].source == "table"


# --------------------------------------------------------------------------- CLI edges
def test_python_m_fastcontact_and_help_defaults():
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    r = subprocess.run([sys.executable, "-m", "fastcontact", "tables", "build", "--help"],
                       capture_output=True, text=True, env=env, timeout=120)
    assert r.returncode == 0
    assert "(default: 0.5)" in r.stdout and "percolation threshold" in r.stdout


def test_tables_defaults_needs_a_folder_outside_a_checkout(monkeypatch):
    from fastcontact.tables import defaults
    monkeypatch.setattr(defaults, "SOURCE_CHECKOUT", None)  # as installed (site-packages)
    code, _, err = cli("tables", "defaults")
    assert code == 2 and "-o DIR" in err and "never written" in err


def test_cache_dir_from_platformdirs(monkeypatch):
    from platformdirs import user_cache_dir
    from fastcontact.tables.cache import table_cache_dir
    monkeypatch.delenv("FASTCONTACT_CACHE_DIR")
    assert table_cache_dir() == Path(user_cache_dir("fastcontact")) / "tables"
    monkeypatch.setenv("FASTCONTACT_CACHE_DIR", "/somewhere")
    assert table_cache_dir() == Path("/somewhere")


def test_missing_optional_package_one_line(monkeypatch):
    import fastcontact.cli as c

    def boom(a, out, err):
        raise ModuleNotFoundError("No module named 'distributed'", name="distributed")
    monkeypatch.setattr(c, "_cmd_sweep", boom)
    code, _, err = cli("sweep", "db", "-o", "x", "--scene", "default")
    assert code == 1 and len(err.strip().splitlines()) == 1
    assert "fastcontact[distributed]" in err and "Traceback" not in err


def test_missing_matplotlib_skips_figures_with_one_line(tmp_path, monkeypatch):
    import importlib.util
    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec",
                        lambda name, *a: None if name == "matplotlib" else real(name, *a))
    code, out, err = cli("run", "--default", "-o", tmp_path / "o", "-q")
    assert code == 0, err
    assert "matplotlib is not installed" in err and len(err.strip().splitlines()) == 1
    assert (tmp_path / "o" / "results.parquet").is_file() and (tmp_path / "o" / "summary.txt").is_file()
    assert not (tmp_path / "o" / "figures").exists()
    rec = json.loads((tmp_path / "o" / "build_record.json").read_text())
    assert "not made" in rec["figures_note"]
