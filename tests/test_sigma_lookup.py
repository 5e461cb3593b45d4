"""The tables' σ̄ lookup is monotone in ln p̄ on every interval of every embedded table.

σ_eff(p) is non-increasing in the contact pressure (Lorenz & Persson 2010, arXiv:1004.1037,
eqs. 25–32 with A(ζ) increasing in p), so the interpolated ln σ̄ must stay between the two
node values of its interval. The reference is the stored node columns themselves; the
quintic Hermite is checked at interior points. The asphalt_072mm critical-junction table
holds one interval next to percolation (σ̄ from 3e-23 to 1e-90 over 0.036 in ln p̄) where the
quintic overshot to σ̄ ~ 1e-13 (and to inf on a level table of asperity_levels).
"""
import math

import numpy as np
import pytest

from fastcontact.defaults import load_default_tables
from fastcontact.kernels.lookup import k_sigma_of_lnp
from fastcontact.squeeze.asperity import asperity_levels

NAMES = ("asphalt_024mm", "asphalt_072mm", "copper_012mm", "pmma_34um")


@pytest.mark.parametrize("name", NAMES)
def test_ln_sigma_between_its_nodes(name):
    tab = load_default_tables(name)
    t = np.linspace(0.0, 1.0, 41)[1:-1]
    for theory in tab.theories:
        kd = tab.kernel_data(theory)
        for i in range(kd.n_open - 1):
            a, b = kd.lnp[i], kd.lnp[i + 1]
            y0, y1 = kd.lnsig[i], kd.lnsig[i + 1]
            ys = np.array([math.log(k_sigma_of_lnp(kd, a + (b - a) * s)) for s in t])
            lo, hi = min(y0, y1), max(y0, y1)
            assert np.all((ys >= lo) & (ys <= hi)), (theory, i, a, b, y0, y1, ys.min(), ys.max())


def test_unresolved_interval_is_monotone_and_below_its_left_node():
    kd = load_default_tables("asphalt_072mm").kernel_data("critical_junction")
    jumps = np.diff(kd.lnsig[:kd.n_open])
    i = int(np.argmin(jumps))  # the steepest interval: the one next to percolation
    assert jumps[i] < -100  # tens of decades in one interval: the case this guards
    xs = np.linspace(kd.lnp[i], kd.lnp[i + 1], 201)
    s = np.array([k_sigma_of_lnp(kd, x) for x in xs])
    assert np.all(np.diff(s) <= 0) and s[0] == pytest.approx(math.exp(kd.lnsig[i]), rel=1e-12)


def test_asperity_levels_next_to_percolation_runs():
    # crashed with "cannot convert float NaN to integer" (the level tables' σ̄ overshot to inf)
    tab = load_default_tables("asphalt_072mm")
    df = asperity_levels(tables=tab, theory="critical_junction", zetas=[1.0, 2.0, 4.0],
                         p0=3e5, E_star=1e7, R=0.01, eta=1e-3)
    assert len(df) == 3
    ok = ~df["trapped"].to_numpy(bool)
    assert np.all(np.isfinite(df.loc[ok, "t_star"].to_numpy(float)))
    assert np.all(df["u_inf"].to_numpy(float) > 0)


def test_seal_lookups_agree_with_the_table_lookup_on_the_unresolved_interval():
    # the seal engine keeps two more copies of the table's σ̄ interpolant (value + slope, and a
    # packed copy for its innermost loop); they must take the same linear branch
    from fastcontact.seal._lookup import _tab_sig, table_sig_d
    from fastcontact.seal.context import seal_context

    tab = load_default_tables("asphalt_072mm")
    kd = tab.kernel_data("critical_junction")
    sc = seal_context(tab, "critical_junction").rec
    i = int(np.argmin(np.diff(kd.lnsig[:kd.n_open])))
    for x in np.linspace(kd.lnp[i - 1], kd.lnp[i + 1], 301):
        ref = k_sigma_of_lnp(kd, x)
        assert table_sig_d(kd, x)[0] == ref
        assert _tab_sig(sc.TQ, sc.TQB, sc.HS, x) == ref
