"""Generalized Bruggeman medium, theory comparison and joint calibration (issue 13)."""
import math

import numpy as np
import pandas as pd
import pytest

import fastcontact as fc
from fastcontact import contact
import fastcontact.conductivity as cond
from fastcontact.validation import Calibration, calibrate, compare_theories
from fastcontact.validation import emt
from fastcontact.validation.compare import read_reference, theory_sigma, write_reference

E = 1e7
ETA = 1e-3


@pytest.fixture(scope="module")
def psd():
    q0 = 2 * math.pi / 1e-3
    return fc.SelfAffinePSD(h_rms=1e-6, hurst=0.8, q0=q0, q1=32 * q0, q_roll=4 * q0)


def test_threshold_half_reproduces_the_shipped_emt(psd):
    p = contact.percolation_pressure(psd, E, np.array([0.001, 0.02, 0.1, 0.3, 0.45, 0.495]))
    shipped, perc = cond.conductivity(psd, p, E, ETA, "emt")
    ours = emt.emt_conductivity(psd, p, E, ETA, threshold=0.5)
    assert not perc.any()
    # independent quadratures (adaptive Gauss-Kronrod vs doubled Gauss-Legendre): 1e-9
    np.testing.assert_allclose(ours, shipped, rtol=1e-9)


def test_generalized_emt_two_phase_closed_form():
    # one open phase σ1 (weight 1-A1) + contact (A1): σ_m = σ1 (k(1-A1) - A1)/k, k = A_c/(1-A_c)
    for A_c in (0.3, 0.5, 0.65):
        k = A_c / (1 - A_c)
        for A1 in (0.0, 0.1, 0.25, 0.29):
            s = emt._solve(np.array([1.0 - A1]), np.array([2.5]), A1, k)
            assert s == pytest.approx(2.5 * (k * (1 - A1) - A1) / k, rel=1e-12)
        assert emt._solve(np.array([1 - A_c]), np.array([2.5]), A_c, k) == 0.0


def test_threshold_moves_the_flow_stop(psd):
    for A_c in (0.35, 0.45):
        p_stop = contact.percolation_pressure(psd, E, A_c)
        below = emt.emt_conductivity(psd, [p_stop * 0.98], E, ETA, threshold=A_c)
        above = emt.emt_conductivity(psd, [p_stop * 1.02], E, ETA, threshold=A_c)
        assert below[0] > 0 and above[0] == 0.0
    with pytest.raises(ValueError, match="emt_threshold"):
        emt.threshold_k(1.0)


def _synthetic_reference(psd, truth, theory):
    """A reference made by the theory itself with known constants (tests the fitter only)."""
    A = np.array([0.02, 0.08, 0.16, 0.25, 0.35])
    p = contact.percolation_pressure(psd, E, A)
    u = contact.mean_separation(psd, p, E, gamma=truth["gamma"])
    s = theory_sigma(psd, p, E, ETA, theory, **truth)
    thr = truth["a_perc"] if theory == "critical_junction" else truth["emt_threshold"]
    df = pd.DataFrame({"p0": p, "u_mean": u, "sigma_eff": s})
    df.attrs = {"eta": ETA, "flow_stop_pressure": float(contact.percolation_pressure(psd, E, thr))}
    return df


def test_calibration_recovers_critical_junction_constants(psd):
    truth = {"gamma": 0.6, "alpha_cj": 0.7, "a_perc": 0.42, "emt_threshold": 0.5}
    ref = _synthetic_reference(psd, truth, "critical_junction")
    cal = calibrate(psd, E, ref, theories=("critical_junction",))
    assert cal.fitted == ("gamma", "alpha_cj", "a_perc")
    assert cal.gamma == pytest.approx(0.6, rel=1e-4)
    assert cal.alpha_cj == pytest.approx(0.7, rel=1e-4)
    assert cal.a_perc == pytest.approx(0.42, rel=1e-4)
    assert cal.residuals_after["sigma_cj"] < 1e-4 < cal.residuals_before["sigma_cj"]


def test_calibration_recovers_emt_threshold(psd):
    truth = {"gamma": 0.8, "alpha_cj": 1.0, "a_perc": 0.5, "emt_threshold": 0.44}
    ref = _synthetic_reference(psd, truth, "emt")
    cal = calibrate(psd, E, ref, theories=("emt",))
    assert cal.fitted == ("gamma", "emt_threshold")
    assert cal.gamma == pytest.approx(0.8, rel=1e-4)
    assert cal.emt_threshold == pytest.approx(0.44, rel=1e-4)


def test_calibration_with_separations_only_fits_gamma(psd):
    p = contact.percolation_pressure(psd, E, np.array([0.05, 0.1, 0.2]))
    ref = pd.DataFrame({"p0": p, "u_mean": contact.mean_separation(psd, p, E, gamma=0.5)})
    cal = calibrate(psd, E, ref)
    assert cal.fitted == ("gamma",)
    assert cal.gamma == pytest.approx(0.5, rel=1e-4)
    assert (cal.alpha_cj, cal.a_perc, cal.emt_threshold) == (1.0, 0.5, 0.5)


def test_calibration_files_roundtrip(tmp_path):
    cal = Calibration(gamma=0.55, alpha_cj=0.61, a_perc=0.43, emt_threshold=0.41,
                      fitted=("gamma",), residuals_before={"u": 0.3},
                      residuals_after={"u": 0.01}, provenance={"n": 256, "psd": {"h": 1e-6}})
    cal.to_toml(tmp_path / "c.toml")
    assert Calibration.from_toml(tmp_path / "c.toml") == cal
    assert Calibration.from_json(cal.to_json()) == cal
    with pytest.raises(ValueError, match="a_perc"):
        Calibration(a_perc=1.2)
    with pytest.raises(ValueError, match="invalid"):
        Calibration.from_dict({"gamma": 0.5, "bogus": 1})


def test_compare_theory_against_itself(psd, tmp_path):
    truth = {"gamma": 1.0, "alpha_cj": 1.0, "a_perc": 0.5, "emt_threshold": 0.5}
    A = np.geomspace(0.01, 0.45, 30)
    p = contact.percolation_pressure(psd, E, A)
    ref = pd.DataFrame({"p0": p, "area_fraction": contact.area_fraction(psd, p, E),
                        "u_mean": contact.mean_separation(psd, p, E),
                        "sigma_eff": theory_sigma(psd, p, E, ETA, "emt", **truth)})
    ref.attrs = {"eta": ETA, "flow_stop_pressure": float(contact.percolation_pressure(psd, E, 0.5))}
    write_reference(ref, tmp_path / "r.parquet")
    ref = read_reference(tmp_path / "r.parquet")
    assert ref.attrs["eta"] == ETA
    c = compare_theories(psd, E, ref, variants=[("emt", "emt", {})])
    for col in ("area_err", "u_err", "sigma_err"):
        assert np.abs(c[col]).max() < 1e-12, col
    t = c.t_ratio.to_numpy()[1:]
    a = c.area_th.to_numpy()[1:]
    # the reference's PCHIP interpolation on 30 points is the only difference; it grows
    # near the flow stop (A -> 0.5) where ln σ_eff plunges between samples
    assert np.all(np.abs(t[a < 0.35] - 1) < 0.01)
    assert c.attrs["flow_stop"]["emt"]["ratio"] == pytest.approx(1.0, rel=1e-12)
    with pytest.raises(ValueError, match="E_star"):
        compare_theories(psd, -1, ref)


def test_top_level_names():
    import fastcontact.validation as v
    assert fc.calibrate is v.calibrate and fc.Calibration is v.Calibration
    assert fc.compare_theories is v.compare_theories and fc.bem_reference is v.bem_reference
