"""Issue 14.3 in the tables and the seal engine: precompute(anisotropy=γ_T),
Tables.conductivity(direction=), seal_leak(direction=), and the percolation threshold taken
from the tables (calibrated emt_threshold) instead of 0.5.

References: the direct anisotropic solver (``directional_sigma_bar``, validated against
``tests/reference/ext_anisotropy.py``), that reference itself with a threshold A_c, scipy
quadrature of σ_xx for the flat ring, the isotropic generalized medium at γ_T = 1.
"""
from __future__ import annotations

import json
import math
import os
import sys

import numpy as np
import pyarrow.parquet as pq
import pytest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from reference.ext_anisotropy import p_of_u, sigma_fixed, sigma_self_consistent  # noqa: E402

import fastcontact as fc  # noqa: E402
from fastcontact.flow.anisotropy import (  # noqa: E402
    directional_sigma_bar,
    directional_tables,
    precompute_directional,
    tables_for_direction,
)
from fastcontact.flow.conductivity import conductivity  # noqa: E402
from fastcontact.seal import seal_leak  # noqa: E402
from fastcontact.tables import Tables  # noqa: E402

E_STAR, ETA, L_Y = 1e7, 1e-3, 0.1
G_T = 3.0


@pytest.fixture(scope="module")
def psd():
    return fc.SelfAffinePSD(h_rms=5e-6, hurst=0.8, q0=1e4, q1=1e7)


@pytest.fixture(scope="module")
def iso(psd):
    return fc.precompute(psd, theories=("average", "critical_junction", "emt"))


@pytest.fixture(scope="module")
def aniso(psd):
    return fc.precompute(psd, theories=("average", "emt"), anisotropy=G_T)


def test_gamma_one_is_the_isotropic_tables(psd, iso):
    one = fc.precompute(psd, theories=("average", "critical_junction", "emt"), anisotropy=1.0)
    assert one.equals(iso) and one.options == iso.options
    assert one.metadata()["columns_sha256"] == iso.metadata()["columns_sha256"]
    assert "anisotropy" not in one.options and "directional" not in one.info


@pytest.mark.parametrize("theory", ["average", "critical_junction", "emt"])
def test_direction_on_isotropic_tables_is_identical(iso, theory):
    p = np.geomspace(1e2, 1e6, 7)
    ref = iso.conductivity(p, E_STAR, ETA, theory)
    for d in ("x", "y"):
        assert np.array_equal(iso.conductivity(p, E_STAR, ETA, theory, direction=d), ref)
    kw = dict(p0=5e4, dp=np.array([1e3, 2e4, 4.5e4]), L=5e-3, L_y=L_Y, E_star=E_STAR, eta=ETA,
              theory=theory)
    base = seal_leak(iso, **kw)
    assert seal_leak(iso, direction="y", **kw).equals(base)


def test_anisotropic_tables_record_and_digest(aniso, tmp_path):
    assert aniso.options["anisotropy"] == G_T
    assert aniso.options["anisotropy_form"] == "self_consistent"
    d = aniso.info["directional"]
    assert d["anisotropy"] == G_T and max(d["interpolation_error"].values()) <= 1e-6
    # the adaptive quadrature in A met its tolerance at every node and midpoint
    q = d["quadrature"]
    assert q["rule"].startswith("adaptive") and q["tolerance"] == aniso.options["emt_tol"] == 1e-7
    assert 0.0 < q["max_error_estimate"] <= q["tolerance"] and q["u1_evaluations"] > 0
    assert {"sigma_emt_x", "sigma_emt_y", "percolated_emt_x"} <= set(aniso.data)
    path = aniso.to_parquet(tmp_path / "a.parquet")
    back = Tables.from_parquet(path)
    assert back.equals(aniso) and back.options["anisotropy"] == G_T
    assert back.info["directional"]["quadrature"] == q
    p = np.geomspace(1e2, 1e6, 5)
    assert np.array_equal(back.conductivity(p, E_STAR, ETA, "emt", "y"),
                          aniso.conductivity(p, E_STAR, ETA, "emt", "y"))
    # the digest covers γ_T: a file whose recorded anisotropy is edited is refused
    t = pq.read_table(path)
    meta = json.loads(t.schema.metadata[b"fastcontact"])
    meta["options"]["anisotropy"] = 2.0
    t2 = t.replace_schema_metadata({b"fastcontact": json.dumps(meta).encode()})
    pq.write_table(t2, tmp_path / "b.parquet")
    with pytest.raises(ValueError, match="altered"):
        Tables.from_parquet(tmp_path / "b.parquet")


def test_directional_conductivity_against_direct_solver(psd, aniso):
    """Random pressures (not nodes) against the direct solver: the directional spline is
    verified to 1e-6 at its midpoints; the tables' columns on their own nodes (degree-8 node
    derivatives through the spline's knots) measured <= 2e-8 (with the spline's derivatives
    on 4 points per decade: 2.4e-6)."""
    rng = np.random.default_rng(3)
    p = np.exp(rng.uniform(math.log(aniso.p_range[0] * E_STAR), math.log(0.9e6), 40))
    sx, sy = directional_sigma_bar(psd, p / E_STAR, G_T)
    h3 = psd.h_rms ** 3 / (12 * ETA)
    gx = aniso.conductivity(p, E_STAR, ETA, "emt", direction="x")
    gy = aniso.conductivity(p, E_STAR, ETA, "emt", direction="y")
    np.testing.assert_allclose(gx, sx * h3, rtol=1e-6)
    np.testing.assert_allclose(gy, sy * h3, rtol=1e-6)
    assert np.all(gx > gy)
    # direction=None: the isotropic medium of the angle-averaged spectrum (unchanged column)
    iso_emt = conductivity(psd, p, E_STAR, ETA, "emt")[0]
    np.testing.assert_allclose(aniso.conductivity(p, E_STAR, ETA, "emt"), iso_emt, rtol=3e-6)
    # "average" has no direction
    assert np.array_equal(aniso.conductivity(p, E_STAR, ETA, "average", "x"),
                          aniso.conductivity(p, E_STAR, ETA, "average"))


def test_bad_direction_requests(aniso, iso):
    with pytest.raises(ValueError, match="direction"):
        aniso.conductivity(1e4, E_STAR, ETA, "emt", direction="z")
    with pytest.raises(ValueError, match="critical_junction"):
        tables_for_direction(aniso, "x", "critical_junction")
    with pytest.raises(ValueError, match="direction"):
        seal_leak(iso, p0=5e4, dp=1e3, L=5e-3, L_y=L_Y, E_star=E_STAR, eta=ETA, theory="emt",
                  direction="xy")
    with pytest.raises(ValueError, match="anisotropy"):
        fc.precompute(fc.SelfAffinePSD(h_rms=5e-6, hurst=0.8, q0=1e4, q1=1e7),
                      theories=("average",), anisotropy=2.0)
    with pytest.raises(ValueError, match="anisotropy"):
        fc.precompute(fc.SelfAffinePSD(h_rms=5e-6, hurst=0.8, q0=1e4, q1=1e7),
                      theories=("emt",), anisotropy=0.5)


@pytest.mark.parametrize("direction", ["x", "y"])
def test_seal_direction_against_quadrature(psd, aniso, direction):
    """Flat ring: Q = L_y/L ∫_{p0-p_a}^{p0} σ_dir(p) dp with σ from the direct solver
    (Gauss–Legendre in ln p, no tables)."""
    p0, L, dp = 5e4, 5e-3, 3e4
    got = seal_leak(aniso, p0=p0, dp=dp, L=L, L_y=L_Y, E_star=E_STAR, eta=ETA, theory="emt",
                    direction=direction)
    x, w = np.polynomial.legendre.leggauss(48)
    a, b = math.log(p0 - dp), math.log(p0)
    lp = 0.5 * (a + b) + 0.5 * (b - a) * x
    sx, sy = directional_sigma_bar(psd, np.exp(lp) / E_STAR, G_T)
    s = (sx if direction == "x" else sy) * psd.h_rms ** 3 / (12 * ETA)
    ref = L_Y / L * 0.5 * (b - a) * np.sum(w * s * np.exp(lp))
    assert abs(got.Q[0] / ref - 1) < 1e-4
    view = directional_tables(aniso, None, direction)
    assert seal_leak(view, p0=p0, dp=dp, L=L, L_y=L_Y, E_star=E_STAR, eta=ETA,
                     theory="emt").Q[0] == got.Q[0]
    # Barus fluid on the directional tables (the η(p) engine reads the same view)
    pz = seal_leak(aniso, p0=p0, dp=dp, L=L, L_y=L_Y, E_star=E_STAR, eta=ETA, theory="emt",
                   direction=direction, alpha_pv=1e-5)
    assert 0 < pz.Q[0] < got.Q[0]


# --------------------------------------------------------------------------- thresholds
@pytest.mark.parametrize("p", [1e4, 4e5])
@pytest.mark.parametrize("a_c", [0.4, 0.6])
def test_threshold_against_reference(psd, p, a_c):
    W, sig, A1 = p_of_u(psd, p, E_STAR)
    fx, fy = directional_sigma_bar(psd, p / E_STAR, G_T, form="fixed", emt_threshold=a_c)
    sx, sy = directional_sigma_bar(psd, p / E_STAR, G_T, emt_threshold=a_c)
    ref = [*sigma_fixed(W, sig, A1, G_T, a_c), *sigma_self_consistent(W, sig, A1, G_T, a_c)]
    np.testing.assert_allclose([fx[0], fy[0], sx[0], sy[0]], ref, rtol=2e-8)


@pytest.mark.parametrize("form", ["self_consistent", "fixed"])
def test_threshold_gamma_one_is_generalized_isotropic(psd, form):
    p = np.array([1e2, 1e4, 1e5, 5e5])
    iso = conductivity(psd, p, E_STAR, 1 / 12, "emt", tol=1e-12, emt_threshold=0.4)[0]
    sx, sy = directional_sigma_bar(psd, p / E_STAR, 1.0, form=form, emt_threshold=0.4)
    np.testing.assert_allclose(sx, iso / psd.h_rms ** 3, rtol=2e-9)
    np.testing.assert_allclose(sy, iso / psd.h_rms ** 3, rtol=2e-9)


def test_directional_tables_take_the_threshold_from_the_tables(psd):
    """Calibrated tables (emt_threshold = 0.4): σ_xx, σ_yy close at A(ζ1)/A0 = 0.4, not 0.5."""
    t = fc.precompute(psd, theories=("emt",), points_per_decade=2, refine=False,
                      emt_threshold=0.4)
    d = precompute_directional(t, G_T, tol=1e-4)
    pc = float(fc.contact.percolation_pressure(psd, 1.0, 0.4))
    for k in ("x", "y"):
        assert abs(d.info["percolation_p_over_E"][k] / pc - 1) < 1e-12
        assert d.sigma_bar(1.001 * pc * E_STAR, E_STAR, k) == 0.0
        assert d.sigma_bar(0.98 * pc * E_STAR, E_STAR, k) > 0.0
    assert t.percolation_area("emt") == 0.4
    fixed = precompute_directional(t, G_T, form="fixed", tol=1e-4)
    a_x = G_T * 0.4 / (0.6 + G_T * 0.4)
    assert abs(fixed.info["percolation_p_over_E"]["x"]
               / float(fc.contact.percolation_pressure(psd, 1.0, a_x)) - 1) < 1e-12
    assert directional_tables(t, G_T, "x", form="fixed", directional=fixed
                              ).percolation_area("emt") == pytest.approx(a_x, rel=1e-15)
