"""Issue 13, point 3: calibrated constants in the shipped flow kernels, tables and scenes.

References are independent of the code under test: the generalized Bruggeman medium of
:mod:`fastcontact.validation.emt` (its own Gauss–Legendre quadrature over A and brentq root)
and a brentq root of A(ζ1)/A0 = threshold on :func:`fastcontact.contact.area_fraction`.
"""
from __future__ import annotations

import json
import math
import types

import numpy as np
import pyarrow.parquet as pq
import pytest
from scipy.optimize import brentq

import fastcontact as fc
from fastcontact import contact
from fastcontact.flow import conductivity as cond
from fastcontact.scene import SceneError, load_scene
from fastcontact.tables import Tables, precompute
from fastcontact.tables.cache import obtain_tables
from fastcontact.validation import Calibration, emt

E = 1e7
ETA = 1e-3
Q0 = 2 * math.pi / 1e-3


@pytest.fixture(scope="module")
def psd():
    return fc.SelfAffinePSD(h_rms=1e-6, hurst=0.8, q0=Q0, q1=32 * Q0, q_roll=4 * Q0)


@pytest.fixture(scope="module")
def cal():
    return Calibration(gamma=0.8, alpha_cj=0.7, a_perc=0.43, emt_threshold=0.42,
                       fitted=("gamma", "alpha_cj", "a_perc", "emt_threshold"),
                       residuals_before={"u": 0.3}, residuals_after={"u": 0.05},
                       provenance={"reference": "synthetic test", "seeds": [1, 2]})


@pytest.fixture(scope="module")
def cal_tables(psd, cal):
    return precompute(psd, theories=("critical_junction", "emt"), calibration=cal)


def _pbar_at_area(psd, areas):
    return contact.percolation_pressure(psd, 1.0, np.asarray(areas, dtype=float))


# --------------------------------------------------------------------------- kernels
@pytest.mark.parametrize("almqvist", [False, True])
def test_threshold_half_is_bitwise_the_default(psd, almqvist):
    pb = np.concatenate([_pbar_at_area(psd, [0.001, 0.3, 0.45, 0.499]), [1e-5, 1e-3]])
    a = cond.sigma_bar(psd, pb, "emt", almqvist=almqvist)
    b = cond.sigma_bar(psd, pb, "emt", almqvist=almqvist, emt_threshold=np.float64(0.5))
    assert np.array_equal(a.sigma_bar, b.sigma_bar) and np.array_equal(a.percolated, b.percolated)
    assert np.array_equal(a.details.error_estimate, b.details.error_estimate)
    ca = cond.conductivity(psd, pb * E, E, ETA, "emt", almqvist=almqvist)
    cb = cond.conductivity(psd, pb * E, E, ETA, "emt", almqvist=almqvist, emt_threshold=0.5)
    assert np.array_equal(ca.sigma_eff, cb.sigma_eff)
    # a threshold a hair off 0.5 takes the generalized branch: continuous with 0.5
    c = cond.sigma_bar(psd, pb, "emt", almqvist=almqvist, emt_threshold=0.5 + 1e-13)
    open_ = a.sigma_bar > 1e-100
    assert np.allclose(c.sigma_bar[open_], a.sigma_bar[open_], rtol=1e-8, atol=0)


@pytest.mark.parametrize("threshold", [0.42, 0.6])
def test_threshold_matches_independent_generalized_medium(psd, threshold):
    pb = _pbar_at_area(psd, [0.001, 0.05, 0.2, 0.35, 0.95 * threshold])
    ours = cond.sigma_bar(psd, pb, "emt", emt_threshold=threshold)
    ref = emt.emt_sigma_bar(psd, pb, threshold=threshold)
    assert np.all(ref > 0) and not ours.percolated.any()
    assert np.allclose(ours.sigma_bar, ref, rtol=1e-8, atol=0), ours.sigma_bar / ref - 1
    # and in SI through conductivity()
    sig = cond.conductivity(psd, pb * E, E, ETA, "emt", emt_threshold=threshold).sigma_eff
    assert np.allclose(sig, ref * psd.h_rms ** 3 / (12 * ETA), rtol=1e-8, atol=0)
    # a lower threshold stops the flow earlier: less conductance at the same pressure
    half = cond.sigma_bar(psd, pb, "emt").sigma_bar
    assert np.all(ours.sigma_bar < half) if threshold < 0.5 else np.all(ours.sigma_bar > half)


@pytest.mark.parametrize("threshold", [0.3, 0.42, 0.6])
def test_flow_stops_exactly_at_the_threshold(psd, threshold):
    pc = float(_pbar_at_area(psd, threshold))
    r = cond.sigma_bar(psd, [pc * (1 - 1e-3), pc * (1 + 1e-9), pc * 1.5], "emt",
                       emt_threshold=threshold)
    assert r.sigma_bar[0] > 0 and not r.percolated[0]
    assert np.all(r.sigma_bar[1:] == 0.0) and np.all(r.percolated[1:])
    c = cond.conductivity(psd, [pc * (1 - 1e-3) * E, pc * (1 + 1e-9) * E], E, ETA, "emt",
                          emt_threshold=threshold)
    assert c.sigma_eff[0] > 0 and c.sigma_eff[1] == 0.0 and c.percolated.tolist() == [False, True]


@pytest.mark.parametrize("bad", [0.0, 1.0, -0.2, 1.5, float("nan")])
def test_bad_threshold_names_parameter(psd, bad):
    with pytest.raises(ValueError, match=r"emt_threshold .*\(0, 1\)"):
        cond.conductivity(psd, 1e5, E, ETA, "emt", emt_threshold=bad)
    with pytest.raises(ValueError, match="emt_threshold"):
        precompute(psd, theories=("emt",), emt_threshold=bad)


# --------------------------------------------------------------------------- tables
def test_precompute_calibration_records_constants(psd, cal, cal_tables):
    T = cal_tables
    assert T.options["gamma"] == 0.8 and T.options["alpha_cj"] == 0.7
    assert T.options["a_perc"] == 0.43 and T.options["emt_threshold"] == 0.42
    block = T.info["calibration"]
    assert {k: block[k] for k in ("gamma", "alpha_cj", "a_perc", "emt_threshold")} == \
        {"gamma": 0.8, "alpha_cj": 0.7, "a_perc": 0.43, "emt_threshold": 0.42}
    assert block["provenance"] == {"reference": "synthetic test", "seeds": [1, 2]}
    assert block["fitted"] == ["gamma", "alpha_cj", "a_perc", "emt_threshold"]
    # the tabulated σ̄ are those of the calibrated kernels (interpolation tolerance 2e-7)
    p = _pbar_at_area(psd, [0.01, 0.2, 0.38]) * E
    for th, kw in (("emt", {"emt_threshold": 0.42}), ("critical_junction",
                                                      {"a_perc": 0.43, "alpha_cj": 0.7})):
        direct = cond.conductivity(psd, p, E, ETA, th, gamma=0.8, **kw).sigma_eff
        assert np.allclose(T.conductivity(p, E, ETA, th), direct, rtol=1e-6, atol=0)
    # the same tables as from the options without the calibration object (base grid)
    grid = (-3.0, -0.5, 6)
    plain = precompute(psd, theories=("critical_junction", "emt"), gamma=0.8, alpha_cj=0.7,
                       a_perc=0.43, emt_threshold=0.42, grid=grid, refine=False)
    viacal = precompute(psd, theories=("critical_junction", "emt"), calibration=cal, grid=grid,
                        refine=False)
    assert plain.equals(viacal, rtol=0.0) and "calibration" not in plain.info
    # default tables carry no emt_threshold key (their files and digests are unchanged)
    assert "emt_threshold" not in precompute(psd, theories=("emt",), refine=False).options


def test_calibration_round_trips_through_parquet(cal_tables, tmp_path):
    path = cal_tables.to_parquet(tmp_path / "cal.parquet")
    back = Tables.from_parquet(path)
    assert back.equals(cal_tables, rtol=0.0) and back.options == cal_tables.options
    assert back.info["calibration"] == cal_tables.info["calibration"]
    assert back.percolation_pressure("emt", E) == cal_tables.percolation_pressure("emt", E)
    assert back.metadata()["metadata_sha256"] == cal_tables.metadata()["metadata_sha256"]


@pytest.mark.parametrize("mutate", [
    lambda m: m["info"]["calibration"].__setitem__("emt_threshold", 0.5),
    lambda m: m["info"]["calibration"]["provenance"].__setitem__("reference", "forged"),
    lambda m: m["options"].__setitem__("emt_threshold", 0.45),
    lambda m: m["info"].pop("calibration"),
], ids=["calibration.emt_threshold", "calibration.provenance", "options.emt_threshold",
        "calibration removed"])
def test_edited_calibration_is_refused(cal_tables, tmp_path, mutate):
    path = cal_tables.to_parquet(tmp_path / "t.parquet")
    table = pq.read_table(path)
    meta = json.loads(table.schema.metadata[b"fastcontact"])
    mutate(meta)
    bad = tmp_path / "edited.parquet"
    pq.write_table(table.replace_schema_metadata({b"fastcontact": json.dumps(meta).encode()}), bad)
    with pytest.raises(ValueError, match="metadata_sha256"):
        Tables.from_parquet(bad)
    assert Tables.from_parquet(path).info["calibration"]["emt_threshold"] == 0.42


def test_calibration_conflicts_and_duck_typing(psd, cal):
    with pytest.raises(ValueError, match=r"a_perc = 0\.3 .*calibration sets a_perc = 0\.43"):
        precompute(psd, theories=("critical_junction",), a_perc=0.3, calibration=cal)
    with pytest.raises(ValueError, match=r"emt_threshold = 0\.45 .*calibration"):
        precompute(psd, theories=("emt",), emt_threshold=0.45, calibration=cal)
    with pytest.raises(ValueError, match=r"calibration = .* lacks \['emt_threshold'\]"):
        precompute(psd, theories=("emt",),
                   calibration=types.SimpleNamespace(gamma=1.0, alpha_cj=1.0, a_perc=0.5))
    # the same value as the calibration's is no conflict; any object with the attributes works
    duck = types.SimpleNamespace(gamma=1.0, alpha_cj=1.0, a_perc=0.5, emt_threshold=0.42)
    T = precompute(psd, theories=("emt",), emt_threshold=0.42, calibration=duck, refine=False)
    assert T.options["emt_threshold"] == 0.42
    assert T.info["calibration"]["provenance"] == {} and T.info["calibration"]["fitted"] == []


@pytest.mark.parametrize("theory", ["critical_junction", "emt"])
def test_percolation_pressure_is_the_area_root(psd, cal_tables, theory):
    thr = 0.43 if theory == "critical_junction" else 0.42

    def f(p):
        return float(contact.area_fraction(psd, p, E)) - thr

    root = brentq(f, 1e-6 * E, 10 * E, xtol=1e-12, rtol=1e-14)
    got = cal_tables.percolation_pressure(theory, E)
    assert got == pytest.approx(root, rel=1e-10)
    # the tables agree with it: open below, percolated (σ = 0) above
    assert not cal_tables.percolated(got * (1 - 1e-6), E, theory)
    assert cal_tables.percolated(got * (1 + 1e-6), E, theory)
    assert cal_tables.conductivity(got * (1 + 1e-6), E, ETA, theory) == 0.0
    assert cal_tables.conductivity(got * 0.9, E, ETA, theory) > 0.0


# --------------------------------------------------------------------------- scenes
def _scene(tmp_path, **tables):
    return {
        "title": "calibrated",
        "study": {"kind": "squeeze", "theory": ["critical_junction", "emt"], "p0": "0.2 MPa",
                  "ratios": [1.1]},
        "surfaces": {"s1": {"h_rms": 1e-6, "hurst": 0.8, "q0": Q0, "q1": 32 * Q0,
                            "q_roll": 4 * Q0}},
        "material": {"E_star": "10 MPa"},
        "fluid": {"eta": "1 mPa s"},
        "geometry": {"R": "1 cm"},
        "tables": tables,
    }


def test_scene_calibration_builds_calibrated_tables(psd, cal, tmp_path):
    (tmp_path / "sub").mkdir()
    cal.to_toml(tmp_path / "sub" / "cal.toml")
    scene = load_scene(_scene(tmp_path, calibration="sub/cal.toml"), base_dir=tmp_path)
    assert scene.table_options == {"gamma": 0.8, "a_perc": 0.43, "alpha_cj": 0.7,
                                   "emt_threshold": 0.42}
    spec = next(iter(scene.surfaces.values()))
    T, rec = obtain_tables(spec, scene.theories, dict(scene.table_options))
    assert T.surface.fingerprint() == psd.fingerprint()
    assert rec.options["emt_threshold"] == 0.42 and T.options["a_perc"] == 0.43
    assert T.percolation_pressure("emt", E) == pytest.approx(
        float(contact.percolation_pressure(psd, E, 0.42)), rel=1e-12)
    # same value twice is fine; a different one, a missing or a broken file is reported
    load_scene(_scene(tmp_path, calibration="sub/cal.toml", a_perc=0.43), base_dir=tmp_path)
    with pytest.raises(SceneError, match=r"tables.a_perc = 0.3: conflicts with tables.calibration"):
        load_scene(_scene(tmp_path, calibration="sub/cal.toml", a_perc=0.3), base_dir=tmp_path)
    with pytest.raises(SceneError, match=r"tables.calibration = 'nope.toml': file not found"):
        load_scene(_scene(tmp_path, calibration="nope.toml"), base_dir=tmp_path)
    # a prebuilt table file (default tables: threshold 0.5) does not satisfy the calibration
    sc = _scene(tmp_path, calibration="sub/cal.toml")
    sc["surfaces"] = {"a": {"table": "asphalt_024mm"}}
    with pytest.raises(SceneError, match=r"built with emt_threshold = 0.5 but tables"):
        load_scene(sc, base_dir=tmp_path)
    (tmp_path / "bad.toml").write_text("gamma = 2.0\n")
    with pytest.raises(SceneError, match=r"tables.calibration = 'bad.toml': not a calibration"):
        load_scene(_scene(tmp_path, calibration="bad.toml"), base_dir=tmp_path)


def test_reading_a_calibration_needs_no_bem_extra(tmp_path, cal):
    """Scenes read the calibration with plain TOML: ContactMechanics is never imported."""
    import subprocess
    import sys
    cal.to_toml(tmp_path / "cal.toml")
    code = ("import sys; sys.modules['ContactMechanics'] = None; "
            "sys.modules['SurfaceTopography'] = None; "
            "from fastcontact.scene import load_scene; "
            f"s = load_scene({_scene(tmp_path, calibration='cal.toml')!r}, base_dir={str(tmp_path)!r}); "
            "assert s.table_options['emt_threshold'] == 0.42, s.table_options; "
            "assert 'ContactMechanics' not in [m for m in sys.modules if sys.modules[m]]")
    subprocess.run([sys.executable, "-c", code], check=True)


# --------------------------------------------------------------------------- CLI
def test_cli_tables_build_with_calibration(cal, tmp_path):
    import io
    from fastcontact.cli import main
    cal.to_toml(tmp_path / "cal.toml")
    args = ["tables", "build", "--h-rms", "1e-6", "--hurst", "0.8", "--q0", repr(Q0),
            "--q1", repr(32 * Q0), "--q-roll", repr(4 * Q0), "--theories", "emt"]
    out, err = io.StringIO(), io.StringIO()
    code = main(args + ["--calibration", str(tmp_path / "cal.toml"), "-o",
                        str(tmp_path / "t.parquet")], out=out, err=err)
    assert code == 0, err.getvalue()
    T = Tables.from_parquet(tmp_path / "t.parquet")
    assert T.options["emt_threshold"] == 0.42 and T.info["calibration"]["gamma"] == 0.8
    out, err = io.StringIO(), io.StringIO()
    code = main(args + ["--calibration", str(tmp_path / "cal.toml"), "--emt-threshold", "0.45",
                        "-o", str(tmp_path / "u.parquet")], out=out, err=err)
    assert code != 0 and "emt_threshold = 0.45" in err.getvalue()
    assert not (tmp_path / "u.parquet").exists()
