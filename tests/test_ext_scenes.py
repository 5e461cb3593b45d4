"""Issue 14.4: scenes and CLI expose each extension; a scene that does not ask for one
computes nothing extra; tables built with an extension record it in their provenance.

References: the engines called directly (their own tests check them against independent
solutions); scenes must return exactly their numbers.
"""
from __future__ import annotations

import io
import json

import numpy as np
import pytest

from fastcontact.cli import main
from fastcontact.scene import SceneError, load_scene, run_scene
from fastcontact.seal import seal_leak
from fastcontact.squeeze.asperity import asperity_summary
from fastcontact.squeeze.tire import tire_footprint
from fastcontact.squeeze.viscosity import squeeze_out_piezo
from fastcontact.tables import Tables

SA = dict(h_rms="5 um", hurst=0.8, q0="1e4 1/m", q1="1e7 1/m")
E_STAR, ETA = 1e7, 1e-3


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory, monkeypatch):
    monkeypatch.setenv("FASTCONTACT_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "table_cache"))


def scene(kind, study, **over):
    d = {"title": "t", "study": dict(kind=kind, **study), "surfaces": {"s": dict(SA)},
         "material": {"E_star": "10 MPa"}, "fluid": {"eta": "1 mPa s"},
         "geometry": {"R": "1 cm"}}
    d.update(over)
    return d


def run(sc, tmp_path, name="o"):
    return run_scene(load_scene(sc), tmp_path / name, make_figures=False)["results"]


def _tables(tmp_path, name="o"):
    rec = json.loads((tmp_path / name / "build_record.json").read_text())
    return Tables.from_parquet(rec["tables"][0]["path"]), rec


SEAL_GEOM = {"L": "5 mm", "L_y": "10 cm"}
SEAL = {"theory": "emt", "p0": "50 kPa", "dp": ["10 kPa", "40 kPa"]}


def test_no_extension_computes_nothing_extra(tmp_path, monkeypatch):
    def boom(*a, **k):
        raise AssertionError("an extension engine ran for a scene that did not ask for it")

    import fastcontact.flow.anisotropy as an
    import fastcontact.seal.api as seal_api
    import fastcontact.squeeze.tire_piezo as tp
    import fastcontact.squeeze.viscosity as sv
    monkeypatch.setattr(sv, "squeeze_out_piezo", boom)
    monkeypatch.setattr(seal_api, "seal_leak_piezo", boom)
    monkeypatch.setattr(tp, "barus_tire_columns", boom)
    monkeypatch.setattr(an, "precompute_directional", boom)
    monkeypatch.setattr(an, "tables_for_direction", boom)
    r1 = run(scene("squeeze", {"theory": "emt", "p0": "0.2 MPa"}), tmp_path, "sq")
    r2 = run(scene("tire", {"theory": "emt", "p0": "0.2 MPa", "footprint_length": "10 cm",
                            "speed": "3 m/s", "u_start": "50 um"}), tmp_path, "ti")
    r3 = run(scene("seal", SEAL, geometry=SEAL_GEOM), tmp_path, "se")
    assert "alpha_pv" not in r1 and "alpha_pv" not in r2 and "alpha_pv" not in r3
    T, rec = _tables(tmp_path, "se")
    assert "anisotropy" not in T.options and "sigma_emt_x" not in T.data


def test_squeeze_alpha_pv(tmp_path):
    res = run(scene("squeeze", {"theory": "emt", "p0": "0.2 MPa",
                                "alpha_pv": ["0 1/Pa", "2 1/MPa"]}), tmp_path)
    base = run(scene("squeeze", {"theory": "emt", "p0": "0.2 MPa"}), tmp_path, "b")
    assert list(res.alpha_pv) == [0.0, 2e-6]
    for c in ("u_inf", "t_star", "t_ratio_1.1", "t_relax", "status"):
        assert res[c].iloc[0] == base[c].iloc[0], c            # α = 0: the base engine
    T, _ = _tables(tmp_path)
    # a two-row study takes the per-case quadrature (the method is chosen by the study's size)
    ref = squeeze_out_piezo(T, p0=2e5, E_star=E_STAR, R=0.01, eta=ETA, alpha_pv=2e-6,
                            theory="emt", ratios=(1.1, 1.01, 1.001), du=(1e-6,), method="quad")
    for c in ("u_inf", "t_star", "t_ratio_1.1", "t_du_1e-06"):
        assert res[c].iloc[1] == ref[c][0], c
    assert np.isnan(res["t_relax"].iloc[1])                    # not produced by that engine
    assert res.error.iloc[1] == ""


def test_squeeze_alpha_pv_times(tmp_path):
    """ū(t) with a Barus fluid in a scene: the u_at columns are the Barus engine's."""
    res = run(scene("squeeze", {"theory": "emt", "p0": "0.2 MPa", "times": ["1 ms", "20 ms"],
                                "alpha_pv": ["0 1/Pa", "2 1/MPa"]}), tmp_path)
    T, _ = _tables(tmp_path)
    ref = squeeze_out_piezo(T, p0=2e5, E_star=E_STAR, R=0.01, eta=ETA, alpha_pv=2e-6,
                            theory="emt", ratios=(1.1, 1.01, 1.001), du=(1e-6,),
                            times=(1e-3, 2e-2), method="quad")
    for c in ("u_at_0.001", "u_at_0.02"):
        assert res[c].iloc[1] == ref[c][0], c
        assert res[c].iloc[1] > res[c].iloc[0] > res.u_inf.iloc[0]   # the oil drains slower


def test_tire_alpha_pv(tmp_path):
    st = {"theory": "emt", "p0": "0.2 MPa", "footprint_length": "10 cm", "speed": "3 m/s",
          "u_start": "50 um", "alpha_pv": ["0 1/Pa", "2 1/MPa"]}
    res = run(scene("tire", st), tmp_path)
    T, _ = _tables(tmp_path)
    ref = tire_footprint(T, p0=2e5, E_star=E_STAR, R=0.01, eta=ETA, footprint_length=0.1,
                         speed=3.0, theory="emt", u_start=50e-6, alpha_pv=np.array([0, 2e-6]))
    for c in ("t_star", "u_exit", "t_du", "squeeze_complete"):
        np.testing.assert_array_equal(res[c].to_numpy(), ref[c].to_numpy())
    assert res.u_exit.iloc[1] > res.u_exit.iloc[0]


@pytest.mark.parametrize("kind", ["squeeze", "tire"])
def test_start_below_equilibrium_explained(tmp_path, kind):
    """A case that starts at or below ū∞ gets NaN times and an error saying why, with or
    without a Barus fluid; the other cases of the scene are computed."""
    st = {"theory": "emt", "p0": "0.2 MPa", "u_start": ["0.1 um", "1 mm"],
          "alpha_pv": ["0 1/Pa", "2 1/MPa"]}
    if kind == "tire":
        st.update({"footprint_length": "10 cm", "speed": "3 m/s"})
    res = run(scene(kind, st), tmp_path)
    T, _ = _tables(tmp_path)
    u_inf = float(tire_footprint(T, p0=2e5, E_star=E_STAR, R=0.01, eta=ETA,
                                 footprint_length=0.1, speed=3.0, theory="emt")["u_inf"][0])
    assert 1e-7 < u_inf < 1e-3
    low = res.u_start.to_numpy() < u_inf
    assert low.sum() == 2 and (~low).sum() == 2
    assert res.error[low].str.startswith("start_below_equilibrium").all()
    assert np.isnan(res.t_star[low]).all()
    assert (res.error[~low] == "").all() and np.isfinite(res.t_star[~low]).all()


@pytest.mark.parametrize("law", ["barus", "roelands"])
def test_seal_viscosity(tmp_path, law):
    st = dict(SEAL, alpha_pv=["0 1/Pa", "20 1/MPa"], viscosity=law)
    if law == "roelands":
        st["roelands_p_r"] = "100 kPa"
    res = run(scene("seal", st, geometry=SEAL_GEOM), tmp_path)
    T, _ = _tables(tmp_path)
    kw = dict(p0=5e4, dp=np.array([1e4, 4e4]), L=5e-3, L_y=0.1, E_star=E_STAR, eta=ETA,
              theory="emt")
    base = seal_leak(T, **kw)
    ext = seal_leak(T, alpha_pv=2e-5, viscosity=law,
                    **(dict(roelands_p_r=1e5) if law == "roelands" else {}), **kw)
    zero = res[res.alpha_pv == 0.0].reset_index(drop=True)
    pos = res[res.alpha_pv > 0.0].reset_index(drop=True)
    np.testing.assert_array_equal(zero.Q.to_numpy(float), base.Q.to_numpy())
    np.testing.assert_array_equal(pos.Q.to_numpy(float), ext.Q.to_numpy())
    np.testing.assert_array_equal(pos.open_inlet.to_numpy(float), 0.0)
    assert np.all(pos.Q.to_numpy(float) < zero.Q.to_numpy(float))


def test_seal_anisotropic_tables_and_direction(tmp_path):
    sx = scene("seal", dict(SEAL, direction="x"), geometry=SEAL_GEOM, tables={"anisotropy": 3})
    sy = scene("seal", dict(SEAL, direction="y"), geometry=SEAL_GEOM, tables={"anisotropy": 3})
    rx, ry = run(sx, tmp_path, "x"), run(sy, tmp_path, "y")
    T, rec = _tables(tmp_path, "x")
    assert T.options["anisotropy"] == 3.0 and rec["tables"][0]["options"]["anisotropy"] == 3.0
    assert "directional" in T.info and "sigma_emt_y" in T.data
    _, rec_y = _tables(tmp_path, "y")
    assert rec_y["tables"][0]["action"] == "reused"            # one cached table, both ways
    meta = json.loads((tmp_path / "x" / "build_record.json").read_text())
    assert meta["tables"][0]["columns_sha256"] == T.metadata()["columns_sha256"]
    kw = dict(p0=5e4, dp=np.array([1e4, 4e4]), L=5e-3, L_y=0.1, E_star=E_STAR, eta=ETA,
              theory="emt")
    np.testing.assert_array_equal(rx.Q.to_numpy(float), seal_leak(T, direction="x", **kw).Q)
    np.testing.assert_array_equal(ry.Q.to_numpy(float), seal_leak(T, direction="y", **kw).Q)
    assert np.all(rx.Q.to_numpy(float) > ry.Q.to_numpy(float))
    # direction on isotropic tables: the isotropic result (documented), not an error
    r_iso = run(scene("seal", dict(SEAL, direction="y"), geometry=SEAL_GEOM), tmp_path, "i")
    r_none = run(scene("seal", SEAL, geometry=SEAL_GEOM), tmp_path, "n")
    np.testing.assert_array_equal(r_iso.Q.to_numpy(float), r_none.Q.to_numpy(float))


def test_asperity_study(tmp_path):
    st = {"theory": "average", "p0": ["0.1 MPa", "0.2 MPa"], "level_ratio": 4,
          "zeta_max": 64}
    res = run(scene("asperity", st), tmp_path)
    T, _ = _tables(tmp_path)
    ref = asperity_summary(T, p0=np.array([1e5, 2e5]), E_star=E_STAR, R=0.01, eta=ETA,
                           theory="average", level_ratio=4.0, zeta_max=64.0)
    for c in ("zeta_trap", "t_star_base", "t_sequential", "t_parallel", "t_sequential_open"):
        np.testing.assert_array_equal(res[c].to_numpy(float), ref[c].to_numpy(float))
    assert (res.error == "").all() and list(res.n_levels) == [4, 4]


def test_scene_problems_reported():
    cases = [
        (scene("seal", dict(SEAL, roelands_z=0.6), geometry=SEAL_GEOM), "roelands_z"),
        (scene("seal", dict(SEAL, viscosity="roelands"), geometry=SEAL_GEOM), "roelands"),
        (scene("seal", dict(SEAL, theory="critical_junction", direction="x"),
               geometry=SEAL_GEOM, tables={"anisotropy": 3}), "anisotropy"),
        (scene("squeeze", {"theory": "emt", "p0": "0.2 MPa", "alpha_pv": "2 MPa"}),
         "alpha_pv"),
        (scene("squeeze", {"theory": "emt", "p0": "0.2 MPa", "direction": "x"}), "direction"),
        (scene("squeeze", {"theory": "emt", "p0": "0.2 MPa"}, tables={"anisotropy": 0.5}),
         "anisotropy"),
    ]
    for sc, word in cases:
        with pytest.raises(SceneError, match=word):
            load_scene(sc)


def test_cli_tables_build_anisotropy(tmp_path):
    out, err = io.StringIO(), io.StringIO()
    f = tmp_path / "a.parquet"
    code = main(["tables", "build", "--h-rms", "5 um", "--hurst", "0.8", "--q0", "1e4",
                 "--q1", "1e7", "--theories", "average", "emt", "--anisotropy", "2",
                 "-o", str(f)], out=out, err=err)
    assert code == 0, err.getvalue()
    T = Tables.from_parquet(f)
    assert T.options["anisotropy"] == 2.0 and "sigma_emt_x" in T.data
    out = io.StringIO()
    assert main(["tables", "info", str(f)], out=out, err=io.StringIO()) == 0
    assert "anisotropy: gamma_T = 2.0" in out.getvalue()
