"""The squeeze-out engine above the tables' largest separation (issue 15: EMT times off by
~2e-6 there with the old two-parameter tail).

The tables carry direct samples of ū and σ̄ below their lowest pressure (``info["tail"]``);
the engine fits σ̄^(1/3) = v + g(1/v) to them and continues with the closed form
σ̄ = y³ - c y far above. Checked against the direct contact-mechanics core (no tables) and
the independent squeeze-out reference (scipy quad on the direct core).
"""
from __future__ import annotations

import math
import os
import sys

import numpy as np
import pytest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from reference.squeeze_reference import SqueezeReference, tau0  # noqa: E402

from fastcontact.contact import contact_pressure  # noqa: E402
from fastcontact.flow.conductivity import sigma_bar  # noqa: E402
from fastcontact.squeeze import squeeze_model, squeeze_out  # noqa: E402
from fastcontact.squeeze import _kernels as qk  # noqa: E402
from fastcontact.tables.tail import TAIL_TOL  # noqa: E402
from fastcontact.tables import Tables, precompute  # noqa: E402
from fastcontact.tables.defaults import default_surface  # noqa: E402
from fastcontact._core.vocab import column_name  # noqa: E402

NAME = "asphalt_072mm"
E, ETA, R = 1e7, 1e-3, 1e-2


@pytest.fixture(scope="module")
def psd():
    return default_surface(NAME)


@pytest.fixture(scope="module")
def tabs(psd):
    return precompute(psd, theories=("critical_junction", "emt"))


def _direct_sigma(psd, v, theory):
    """σ̄ of the direct core at ū = v h_rms (no tables)."""
    p = float(contact_pressure(psd, v * psd.h_rms, 1.0))
    return float(sigma_bar(psd, np.array([p]), theory).sigma_bar[0]), p


def test_tables_carry_tail_samples_below_their_range(tabs):
    tail = tabs.info["tail"]
    lnp = np.asarray(tail["ln_p_over_E"])
    assert lnp.size >= 7 and np.all(lnp < math.log(tabs.p_range[0]))
    assert np.all(np.diff(tail["u_over_h"]) > 0)
    assert max(tail["u_over_h"]) > 5 * tabs.u_range[1]


@pytest.mark.parametrize("theory", ["emt", "critical_junction"])
def test_tail_sigma_matches_the_direct_core_between_samples(psd, tabs, theory):
    m = squeeze_model(tabs, theory)
    for v in (33.0, 41.0, 63.0, 97.0, 170.0, 290.0, min(0.999 * m.mp.v_ext, 380.0)):
        want, p = _direct_sigma(psd, v, theory)
        got = qk.tail_sigma(m.mp, v)[0]
        assert abs(got / want - 1.0) < 2e-8, (theory, v, got, want)
        # the contact pressure of the tail, eq. (3) continued: ln π linear in v (measured
        # ≤ 1.3e-9 absolute in ln π up to 380 h_rms with the top's exact slope u0; 7e-9 to
        # 2.4e-8 with the forward difference used before)
        lnp_tail = m.mp.x_min - (v - m.mp.v_top) / m.mp.u0
        assert abs(lnp_tail - math.log(p)) < 5e-9, (theory, v, lnp_tail - math.log(p))


@pytest.mark.parametrize("theory", ["emt", "critical_junction"])
def test_closed_form_above_v_ext_continues_the_fit(tabs, theory):
    mp = squeeze_model(tabs, theory).mp
    for v in mp.v_ext * np.array([1.0, 1.3, 2.0, 5.0, 50.0, 1e4]):
        y = v + mp.d
        far = y ** 3 - mp.c * y
        assert abs(far / qk.tail_sigma(mp, v)[0] - 1.0) < 1.01 * TAIL_TOL, (theory, v)


@pytest.mark.parametrize("pbar, v_start", [(1e-12, None), (1e-12, 60.0), (3e-10, 150.0)])
def test_emt_times_of_films_starting_above_the_table_top(psd, tabs, pbar, v_start):
    """Old tail: 2.8e-6 (default start at ~39 h_rms) to 1.2e-5 (start at 60 h_rms)."""
    ref = SqueezeReference(psd, E, "emt", pbar * E)
    t0 = tau0(ETA, R, psd.h_rms, pbar * E)
    kw = {} if v_start is None else {"u_start": v_start * psd.h_rms}
    df = squeeze_out(tabs, p0=pbar * E, E_star=E, R=R, eta=ETA, theory="emt", ratios=(1.1,),
                     **kw)
    want = ref.t_ratio(1.1, v_start) * t0
    assert abs(float(df["t_ratio_1.1"].iloc[0]) / want - 1.0) < 1e-6


def test_tables_without_tail_samples_keep_the_old_tail(tabs):
    old = Tables(tabs.surface, tabs.theories, tabs.options, tabs.grid, tabs.zeta_grid,
                 tabs.data, {k: v for k, v in tabs.info.items() if k != "tail"})
    m_old, m_new = squeeze_model(old, "emt"), squeeze_model(tabs, "emt")
    assert "fit_error" not in m_old.tail and m_new.tail["fit_error"] < 1e-8
    assert m_old.mp.v_ext < m_new.mp.v_ext
    # inside the table the tail does not enter: both agree to the primitive's accuracy
    kw = dict(p0=1e3, E_star=E, R=R, eta=ETA, theory="emt", ratios=(1.1, 1.01),
              u_start=20 * tabs.h_rms)
    a, b = squeeze_out(old, **kw), squeeze_out(tabs, **kw)
    for c in ("t_ratio_1.1", "t_ratio_1.01"):
        assert abs(float(a[c].iloc[0]) / float(b[c].iloc[0]) - 1.0) < 1e-8


@pytest.mark.parametrize("call", ["mean_separation", "sigma_bar", "critical_magnification"])
def test_direct_core_refuses_pressures_where_it_underflows(psd, call):
    """p/E* = 1e-200 used to give ū = inf (unflagged) or a SystemError from the EMT kernel."""
    from fastcontact import contact
    fn = {"mean_separation": lambda: contact.mean_separation(psd, 1e-193, 1e7),
          "sigma_bar": lambda: sigma_bar(psd, np.array([1e-200]), "emt"),
          "critical_magnification": lambda: contact.critical_magnification(psd, 1e-193, 1e7)}
    with pytest.raises(ValueError, match=r"p/E_star = 1e-200 is invalid.*>= 1e-150"):
        fn[call]()


def test_barus_engine_uses_the_same_tail(psd, tabs):
    """The Barus engine (alpha_pv > 0) used σ̄ ∝ v³ above the table top: t off by up to
    3e-3 (critical junction) for a film from 60 h_rms; α → 0 must give the reference."""
    pbar, v_start = 1e-12, 60.0
    for theory in ("emt", "critical_junction"):
        ref = SqueezeReference(psd, E, theory, pbar * E)
        want = ref.t_ratio(1.1, v_start) * tau0(ETA, R, psd.h_rms, pbar * E)
        df = squeeze_out(tabs, p0=pbar * E, E_star=E, R=R, eta=ETA, theory=theory,
                         ratios=(1.1,), u_start=v_start * psd.h_rms, alpha_pv=1e-30)
        assert abs(float(df["t_ratio_1.1"].iloc[0]) / want - 1.0) < 1e-6, theory


@pytest.mark.parametrize("theory", ["emt", "critical_junction"])
def test_du_targets_below_the_resolution_of_u_inf(tabs, theory):
    """Δu = 1e-20 m next to ū∞ = 6 mm: the Barus engine returned t = inf with status "ok",
    the per-case quadrature 13 % less than the fast path. Near equilibrium every path must
    show the exact logarithmic approach t = S ln(1/Δu) + const (equal steps per decade)."""
    du = tuple(10.0 ** -k for k in range(9, 21))
    kw = dict(p0=1e3, E_star=E, R=R, eta=ETA, theory=theory, ratios=(1.1,), du=du)
    cols = [column_name("t_du", d) for d in du]
    for extra in ({}, {"method": "quad"}, {"alpha_pv": 1e-30}):
        df = squeeze_out(tabs, **kw, **extra)
        assert (df["status"] == "ok").all(), extra
        t = df[cols].iloc[0].to_numpy()
        assert np.all(np.isfinite(t)) and np.all(np.diff(t) > 0), extra
        steps = np.diff(t)
        np.testing.assert_allclose(steps, steps[0], rtol=1e-6, err_msg=str(extra))
