"""Issue #6: scenes (units, validation, cases, table cache, build record, outputs), the tire
study and road databases."""
from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

from fastcontact.scene import (SceneError, default_table_path, load_scene, parse_quantity,
                               run_scene, squeeze_columns)

SA = dict(h_rms="10 um", hurst=0.8, q0="1e4 1/m", q1="1e8 1/m")


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory, monkeypatch):
    monkeypatch.setenv("FASTCONTACT_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "table_cache"))


def squeeze_scene(**over):
    sc = {
        "title": "t",
        "study": {"kind": "squeeze", "theory": "average", "p0": "0.2 MPa", "ratios": [1.1, 1.01],
                  "du": ["1 um"]},
        "surfaces": {"s1": dict(SA)},
        "material": {"E": "10 MPa", "nu": 0.5},
        "fluid": {"eta": "1 mPa s"},
        "geometry": {"R": "1 cm"},
    }
    for k, v in over.items():
        sc[k] = v
    return sc


# --------------------------------------------------------------------------- units
@pytest.mark.parametrize("text,dim,value", [
    ("0.2 MPa", "pressure", 2e5), ("11.8 kPa", "pressure", 11.8e3), ("1 bar", "pressure", 1e5),
    ("2 cm", "length", 0.02), ("0.72 mm", "length", 0.72e-3), ("34 um", "length", 34e-6),
    ("34 µm", "length", 34e-6), ("1 mPa s", "viscosity", 1e-3), ("1 mPa·s", "viscosity", 1e-3),
    ("1 cP", "viscosity", 1e-3), ("0.001 Pa*s", "viscosity", 1e-3),
    ("1000 kg/m^3", "density", 1000.0), ("1 g/cm^3", "density", 1000.0),
    ("30 m/s", "velocity", 30.0), ("108 km/h", "velocity", 30.0), ("3 ms", "time", 3e-3),
    ("1e5 1/m", "wavevector", 1e5), ("1 1/mm", "wavevector", 1e3), ("2 N/mm", "force_per_length", 2e3),
    (0.5, "dimensionless", 0.5), (3, "length", 3.0), ("0.25", "length", 0.25),
])
def test_units(text, dim, value):
    assert parse_quantity("k", text, dim) == pytest.approx(value, rel=1e-14)


@pytest.mark.parametrize("text,dim,fragment", [
    ("0.2 MPa s", "pressure", "wrong unit"), ("2 cm", "pressure", "wrong unit"),
    ("2 furlongs", "length", "unknown unit"), ("abc", "length", "not a number"),
    (True, "length", "must be a number"), ("1 m/s/s", "velocity", "more than one"),
    ("inf m", "length", "not a number"),
])
def test_units_bad_name_the_key(text, dim, fragment):
    with pytest.raises(ValueError) as exc:
        parse_quantity("geometry.R", text, dim)
    assert "geometry.R" in str(exc.value) and fragment in str(exc.value)


# --------------------------------------------------------------------------- validation
def test_every_problem_reported_at_once(tmp_path):
    sc = squeeze_scene()
    sc["fluid"] = {"etaa": "1 mPa s"}                          # unknown key (did you mean eta?)
    sc["geometry"] = {"R": "2 MPa"}                            # wrong unit
    sc["surfaces"]["s2"] = {"psd": "nope.csv", "convention": "persson"}   # missing file
    sc["study"]["speed"] = "30 m/s"                            # not used by squeeze
    sc["material"]["nu"] = 0.7                                 # out of range
    sc["bogus"] = 1
    with pytest.raises(SceneError) as exc:
        load_scene(sc, base_dir=tmp_path)
    probs = exc.value.problems
    text = " | ".join(probs)
    assert "fluid.etaa" in text and "did you mean 'eta'" in text
    assert "geometry.R" in text and "wrong unit" in text
    assert "surfaces.s2.psd" in text and "not found" in text
    assert "study.speed" in text and "not used" in text
    assert "material.nu" in text
    assert "bogus" in text
    assert "fluid.eta is missing" in text
    assert len(probs) >= 7


def test_table_surface_needs_theories(tmp_path):
    from fastcontact.psd import SelfAffinePSD
    from fastcontact.tables import precompute
    p = tmp_path / "avg.parquet"
    precompute(SelfAffinePSD(10e-6, 0.8, 1e4, 1e8), theories=("average",)).to_parquet(p)
    sc = squeeze_scene(surfaces={"s": {"table": "avg.parquet"}})
    sc["study"]["theory"] = ["average", "emt"]
    with pytest.raises(SceneError, match=r"surfaces\.s\.table.*needs \['emt'\]"):
        load_scene(sc, base_dir=tmp_path)
    sc["study"]["theory"] = "average"
    assert load_scene(sc, base_dir=tmp_path).surfaces["s"].path == p


def test_default_table_resolution():
    p = default_table_path("asphalt_072mm")
    assert p.is_file() and p.parent.name == "data"
    assert default_table_path("asphalt_072mm.parquet") == p
    with pytest.raises(FileNotFoundError, match="available: .*asphalt_024mm"):
        default_table_path("asphalt_999mm")


def test_axes_ranges_products_and_zip():
    sc = squeeze_scene()
    sc["study"]["p0"] = {"start": "0.1 MPa", "stop": "1 MPa", "num": 3, "log": True}
    sc["fluid"]["eta"] = ["1 mPa s", "10 mPa s"]
    sc["study"]["theory"] = ["average", "emt"]
    s = load_scene(sc)
    cases = s.cases()
    assert len(cases) == 3 * 2 * 2
    assert np.allclose(sorted(set(cases.p0)), [1e5, 10 ** 5.5, 1e6])
    assert set(cases.theory) == {"average", "emt"} and s.theories == ("average", "emt")
    assert np.allclose(cases.E_star, 10e6 / 0.75)
    assert list(cases.case_id) == list(range(12))
    sc["sweep"] = {"combine": "zip"}
    sc["study"]["theory"] = "average"
    sc["fluid"]["eta"] = ["1 mPa s", "2 mPa s", "3 mPa s"]
    z = load_scene(sc).cases()
    assert len(z) == 3 and np.allclose(z.eta, [1e-3, 2e-3, 3e-3])
    sc["fluid"]["eta"] = ["1 mPa s", "2 mPa s"]
    with pytest.raises(SceneError, match="different lengths"):
        load_scene(sc)


def test_bad_range_and_columns():
    sc = squeeze_scene()
    sc["study"]["p0"] = {"start": "0.1 MPa", "stop": "1 m", "num": 0, "logg": True}
    sc["outputs"] = {"columns": ["t_stra"], "figures": ["u_of_tt"]}
    with pytest.raises(SceneError) as exc:
        load_scene(sc)
    t = str(exc.value)
    assert "study.p0.logg" in t and "did you mean 'log'" in t
    assert "study.p0.stop" in t and "wrong unit" in t and "study.p0.num" in t
    assert "unknown column 't_stra'" in t and "did you mean" in t
    assert "u_of_tt" in t and "did you mean 'u_of_t'" in t


# --------------------------------------------------------------------------- running
def test_run_builds_only_needed_theory_and_reuses(tmp_path):
    sc = squeeze_scene(outputs={"columns": ["u_inf", "t_star", "t_ratio_*"]})
    s = load_scene(sc)
    res = run_scene(s, tmp_path / "o1")
    rec = json.loads((tmp_path / "o1" / "build_record.json").read_text())
    assert rec["tables"][0]["action"] in ("built", "reused")
    from fastcontact.tables import Tables
    T = Tables.from_parquet(rec["tables"][0]["path"])
    assert T.theories == ("average",)                    # only what the study asked for
    assert T.metadata()["theories"] == ["average"]
    assert rec["outputs"]["columns"] == ["u_inf", "t_star", "t_ratio_1.1", "t_ratio_1.01"]
    assert rec["outputs"]["figures"] == []
    df = pd.read_parquet(tmp_path / "o1" / "results.parquet")
    assert "t_du_1e-06" not in df and "u_at_1" not in df         # not requested: not computed
    assert {"u_inf", "t_star", "t_ratio_1.1", "t_ratio_1.01", "error"} <= set(df.columns)
    assert (df.error == "").all() and np.all(df["t_ratio_1.1"] < df["t_ratio_1.01"])
    assert not (tmp_path / "o1" / "figures").exists()
    # second run: the cached table is reused
    run_scene(load_scene(sc), tmp_path / "o2")
    rec2 = json.loads((tmp_path / "o2" / "build_record.json").read_text())
    assert rec2["tables"][0]["action"] == "reused"
    assert rec2["tables"][0]["columns_sha256"] == rec["tables"][0]["columns_sha256"]
    # provenance in the Parquet key-value metadata
    meta = json.loads(pq.read_schema(tmp_path / "o1" / "results.parquet").metadata[b"fastcontact"])
    import fastcontact
    assert meta["fastcontact_version"] == fastcontact.__version__
    assert "Lorenz" in meta["paper_reference"] and "Eur. Phys. J. E 32" in meta["paper_reference"]
    assert meta["tables"]["s1"]["columns_sha256"] == rec["tables"][0]["columns_sha256"]
    assert meta["scene"]["kind"] == "squeeze" and "p0" in meta["scene"]["axes"]
    assert res["results"].shape[0] == 1


def test_squeeze_results_match_engine(tmp_path):
    from fastcontact.elasticity import effective_modulus
    from fastcontact.squeeze import squeeze_out
    from fastcontact.tables import Tables
    sc = squeeze_scene(surfaces={"a": {"table": "asphalt_024mm"}})
    sc["study"]["p0"] = ["0.1 MPa", "0.3 MPa"]
    sc["study"]["times"] = ["1 ms"]
    res = run_scene(load_scene(sc), tmp_path / "o")["results"]
    T = Tables.from_parquet(default_table_path("asphalt_024mm"))
    ref = squeeze_out(T, p0=np.array([1e5, 3e5]), E_star=effective_modulus(10e6, 0.5), R=0.01,
                      eta=1e-3, theory="average", ratios=(1.1, 1.01), du=(1e-6,),
                      times=(1e-3,), method="quad")
    for c in ("u_inf", "t_star", "t_ratio_1.1", "t_du_1e-06", "u_at_0.001"):
        assert np.allclose(res[c].to_numpy(float), ref[c].to_numpy(float), rtol=1e-12), c
    assert set(squeeze_columns((1.1,), (1e-6,), (1e-3,))) >= {"t_ratio_1.1", "t_du_1e-06", "u_at_0.001"}


def test_out_of_table_case_is_flagged_not_fatal(tmp_path):
    sc = squeeze_scene(surfaces={"a": {"table": "asphalt_024mm"}})
    sc["study"]["p0"] = ["0.2 MPa", "1000 GPa"]            # the second is far above the table
    res = run_scene(load_scene(sc), tmp_path / "o")["results"]
    assert res.error.iloc[0] == "" and "out_of_table" in res.error.iloc[1]
    assert np.isfinite(res.t_star.iloc[0]) and np.isnan(res.t_star.iloc[1])


# --------------------------------------------------------------------------- tire study
def test_tire_footprint_paper_numbers():
    from fastcontact.elasticity import effective_modulus
    from fastcontact.tables import Tables
    from fastcontact.tire import tire_footprint
    T = Tables.from_parquet(default_table_path("asphalt_024mm"))
    df = tire_footprint(T, p0=0.2e6, E_star=effective_modulus(10e6, 0.5), R=0.02,
                        eta=np.array([1e-3, 1.0]), footprint_length=0.1, speed=30.0,
                        theory="average")
    assert np.allclose(df.t_footprint, 0.1 / 30)
    # paper Sec. 5: "for the smoother road surface 2 it takes ~3e-5 s to reach Δu = 1 µm"
    assert 1e-5 < df.t_du.iloc[0] < 1e-4
    # viscous time scales with η (autonomous ODE, τ ∝ η)
    assert df.t_du.iloc[1] / df.t_du.iloc[0] == pytest.approx(1000.0, rel=1e-6)
    assert np.all(df.squeeze_complete == (df.du_exit <= 1e-6))
    assert bool(df.squeeze_complete.iloc[0]) and not bool(df.squeeze_complete.iloc[1])
    assert np.all(df["t_ratio_1.1"] < df["t_ratio_1.01"]) and np.all(df["t_ratio_1.01"] < df["t_ratio_1.001"])
    assert np.allclose(df.t_star, df["t_ratio_1.01"])
    # inertia-limited estimate beside the viscous one: τ' = (D²ρ/(64 p0))^½, t* = τ' ln(u0/h)
    tau = math.sqrt(0.04 ** 2 * 1000 / (64 * 0.2e6))
    assert np.allclose(df.tau_inertia, tau, rtol=1e-12)
    assert np.allclose(df.t_star_inertia, tau * math.log(1e-2 / T.h_rms), rtol=1e-12)


def test_tire_inertia_paper_value_and_profiles():
    from fastcontact.tables import Tables
    from fastcontact.tire import pressure_profile, profile_factors, tire_footprint
    T = Tables.from_parquet(default_table_path("asphalt_072mm"))
    # paper: D = 2 cm, p0 = 0.3 MPa, ρ = 1000 → τ' = 1.4434e-4 s
    df = tire_footprint(T, p0=0.3e6, E_star=13e6, R=0.01, eta=1e-3, footprint_length=0.1,
                        speed=30, columns=["tau_inertia"])
    assert list(df.columns) == ["tau_inertia"]
    assert df.tau_inertia.iloc[0] == pytest.approx(1.4434e-4, rel=1e-4)
    assert profile_factors("parabolic") == (1.0, pytest.approx(1.5, rel=1e-9))
    x = np.linspace(0, 1, 2001)
    f = pressure_profile([0, 1, 1, 0], x)
    assert np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(x)) == pytest.approx(1.0, rel=1e-6)
    assert f.max() == pytest.approx(1.5)
    mean = tire_footprint(T, p0=0.2e6, E_star=13e6, R=0.02, eta=1e-3, footprint_length=0.1,
                          speed=30, pressure_profile="parabolic", pressure_model="mean")
    peak = tire_footprint(T, p0=0.2e6, E_star=13e6, R=0.02, eta=1e-3, footprint_length=0.1,
                          speed=30, pressure_profile="parabolic", pressure_model="peak")
    assert mean.p_eval.iloc[0] == 0.2e6 and peak.p_eval.iloc[0] == pytest.approx(0.3e6)
    assert peak.u_inf.iloc[0] < mean.u_inf.iloc[0]
    with pytest.raises(ValueError, match="pressure_model"):
        tire_footprint(T, p0=0.2e6, E_star=13e6, R=0.02, eta=1e-3, footprint_length=0.1,
                       speed=30, pressure_model="local")


# --------------------------------------------------------------------------- road databases
def test_road_database_deterministic_and_realistic(tmp_path):
    from fastcontact.psd import TabulatedPSD
    from fastcontact.roaddb import generate_road_database, open_road_database
    a = generate_road_database(tmp_path / "a", 30, seed=7, surfaces_per_part=12)
    b = generate_road_database(tmp_path / "b", 30, seed=7, surfaces_per_part=12)
    c = generate_road_database(tmp_path / "c", 30, seed=8, surfaces_per_part=12)
    fa = sorted(p.name for p in a.iterdir())
    assert fa == ["part-00000.parquet", "part-00001.parquet", "part-00002.parquet"]
    for n in fa:
        assert (a / n).read_bytes() == (b / n).read_bytes()
    da, dc = open_road_database(a), open_road_database(c)
    assert len(da) == 30 and da.fingerprint == open_road_database(b).fingerprint
    assert da.fingerprint != dc.fingerprint
    df = pd.read_parquet(a)
    per = df.groupby("surface_id").first()
    assert per.h_rms.between(1e-4, 1e-3).all() and per.hurst.between(0.7, 0.9).all()
    assert (2 * np.pi / per.q_roll).between(1e-3, 5e-3).all()
    assert per.q1.between(1e5, 1e6).all() and (per.q0 < per.q_roll).all()
    for sid in da.ids[:5]:
        psd = da.psd(sid)
        assert isinstance(psd, TabulatedPSD)
        assert psd.h_rms == pytest.approx(per.loc[sid, "h_rms"], rel=1e-12)
        assert 0.3 <= psd.rms_slope <= 4.0 + 1e-9


def test_road_database_conventions_and_psd_folder(tmp_path):
    from fastcontact.roaddb import generate_road_database, open_road_database
    from fastcontact.topography import write_psd
    p = generate_road_database(tmp_path / "p", 3, seed=1)
    s = generate_road_database(tmp_path / "s", 3, seed=1, convention="surface_topography")
    dp, ds = open_road_database(p), open_road_database(s)
    for sid in dp.ids:
        assert np.allclose(dp.spectrum(sid)[1], ds.spectrum(sid)[1], rtol=1e-14)
    raw = pd.read_parquet(s)
    assert raw.C.iloc[0] == pytest.approx((2 * np.pi) ** 2 * dp.spectrum(dp.ids[0])[1][0], rel=1e-14)
    # a folder of PSD files: ids from the file stems, conventions from Parquet metadata / option
    folder = tmp_path / "files"
    folder.mkdir()
    write_psd(dp.psd(dp.ids[0]), folder / "road_a.parquet", "surface_topography")
    write_psd(dp.psd(dp.ids[1]), folder / "road_b.csv", "persson")
    with pytest.raises(ValueError, match="convention"):
        open_road_database(folder).spectrum("road_b")
    d = open_road_database(folder, convention=None)
    assert d.ids == ["road_a", "road_b"]
    assert np.allclose(d.spectrum("road_a")[1], dp.spectrum(dp.ids[0])[1], rtol=1e-12)
    with pytest.raises(ValueError, match="database"):
        open_road_database(tmp_path / "missing")
