"""Issue 11.1: trapped-fluid rows of squeeze_out / tire_footprint from the trapped side's
time primitive (fastcontact/squeeze/_trap_primitive.py) instead of per-case quadrature,
against the independent quadrature of ``tests/reference/trapped_reference.py`` (panels broken
at the tables' nodes, convergence checked by halving).
"""
from __future__ import annotations

import math
import os
import sys

import numpy as np
import pytest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from reference.trapped_reference import TrappedReference  # noqa: E402

from fastcontact._core.vocab import column_name  # noqa: E402
from fastcontact.squeeze import _kernels as qk  # noqa: E402
from fastcontact.squeeze import squeeze_model, squeeze_out  # noqa: E402
from fastcontact.squeeze.tire import tire_footprint  # noqa: E402
from fastcontact.squeeze import _trap_primitive as tpm  # noqa: E402
from fastcontact.tables import Tables  # noqa: E402
from fastcontact.tables.defaults import default_table_path  # noqa: E402

E = 1e7
ETA = 1e-3
R = 0.01
TOL = 1e-6  # issue 11.5: t within 1e-6 relative, ū - ū_trap within 1e-6 (or 1e-8 ū_trap)


@pytest.fixture(scope="module", params=["asphalt_024mm", "asphalt_072mm"])
def tables(request):
    # asphalt_024mm: the tables' last open node lies above the trap pressure (σ̄'s cubic
    # continuation, a kink at z_split); asphalt_072mm: below (no kink)
    return Tables.from_parquet(default_table_path(request.param))


@pytest.mark.parametrize("theory", ["critical_junction", "emt"])
def test_trapped_rows_against_independent_quadrature(tables, theory):
    m = squeeze_model(tables, theory)
    ref = TrappedReference(m)
    h = m.h_rms
    rng = np.random.default_rng(7)
    n = 12
    x0 = m.x_trap + np.exp(rng.uniform(math.log(2e-8), math.log(m.x_max - m.x_trap), n))
    vs = m.mp.v_trap * rng.uniform(1.3, 40.0, n)
    dv = 0.3 * m.mp.v_trap
    times = np.array([1e-7, 1e-5, 1e-3, 1e-1, 10.0])
    df = squeeze_out(tables, p0=np.exp(x0) * E, E_star=E, R=R, eta=ETA, theory=theory,
                     u_start=vs * h, ratios=(1.5, 3.0), du=(dv * h,), times=times)
    assert (df["status"] == "trapped").all()
    for i in range(n):
        tau = df["tau0"].iloc[i]
        vinf = df["u_inf"].iloc[i] / h
        assert df["u_trap"].iloc[i] == pytest.approx(m.mp.v_trap * h, rel=1e-15)
        for col, vt in (("t_ratio_1.5", 1.5 * vinf), ("t_ratio_3", 3.0 * vinf),
                        (column_name("t_du", dv * h), vinf + dv)):
            got = df[col].iloc[i] / tau
            if vt >= vs[i]:
                assert got == 0.0
            elif vt <= m.mp.v_trap:
                assert got == math.inf
            else:
                r = ref.time(x0[i], vs[i], vt)
                assert abs(got / r - 1.0) < TOL, (col, x0[i], got, r)
        tt = df["t_trap"].iloc[i] / tau
        r = ref.t_trap(x0[i], vs[i])
        assert abs(tt / r - 1.0) < TOL, (x0[i], tt, r)
        for t in times:
            u = df[column_name("u_at", t)].iloc[i] / h
            t_red = t / tau
            if t_red >= tt:
                assert u == m.mp.v_trap
                continue
            assert m.mp.v_trap < u <= vs[i]
            # the forward reference from the start down to the returned ū takes the time
            # asked for: |Δt|/t within TOL, or ū within 1e-8 ū_trap of the true one (Δt
            # times the local speed dū/dt̃ = σ̄ (1 - π_c/π0) bounds that distance)
            if u - m.mp.v_trap < 1e-8 * m.mp.v_trap or u == vs[i]:
                continue
            dt = ref.time(x0[i], vs[i], u) - t_red
            sig, d = qk.state_gap(m.tab, m.mp, x0[i], m.mp.v_trap, u - m.mp.v_trap)
            assert (abs(dt) < TOL * t_red
                    or abs(dt) * sig * d < max(TOL * (u - m.mp.v_trap), 1e-8 * m.mp.v_trap)), \
                (x0[i], t, u, dt)


def test_trapped_rows_match_the_quadrature_columns_and_statuses():
    T = Tables.from_parquet(default_table_path("asphalt_072mm"))
    m = squeeze_model(T, "emt")
    h = m.h_rms
    vb = m.mp.v_trap
    x0 = m.x_trap + np.array([0.01, 0.3, 1.0, 0.3, 0.3, 0.3])
    us = np.array([10.0, 10.0, np.nan, 0.5, 1.0, 1e-6]) * vb * h  # NaN: the default start
    us[2] = np.nan
    p0 = np.exp(x0) * E
    rows = []
    for method in ("fast", "quad"):
        parts = [squeeze_out(T, p0=p0[i], E_star=E, R=R, eta=ETA, theory="emt",
                             u_start=None if np.isnan(us[i]) else us[i], ratios=(1.5, 3.0),
                             times=(0.0, 1e-3, math.inf)) for i in range(x0.size)]
        rows.append(parts)
    for f, q in zip(*rows):
        assert f["status"].iloc[0] == q["status"].iloc[0]
        for col in f.columns:
            a, b = f[col].iloc[0], q[col].iloc[0]
            if isinstance(a, float):
                if math.isnan(b) or math.isinf(b) or b == 0.0:
                    assert a == b or (math.isnan(a) and math.isnan(b)), (col, a, b)
                else:
                    assert abs(a / b - 1.0) < 1e-4, (col, a, b)  # the quadrature's accuracy
            else:
                assert a == b, (col, a, b)
    st = [r["status"].iloc[0] for r in rows[0]]
    assert st[:5] == ["trapped"] * 5 and st[5] == "start_below_equilibrium"
    # a start between ū∞ and ū_trap: never drains further, t_trap 0, every target below inf
    r = rows[0][3]
    assert r["t_trap"].iloc[0] == 0.0 and r["t_ratio_1.5"].iloc[0] in (0.0, math.inf)
    assert r["u_at_0.001"].iloc[0] == us[3]


def test_trapped_side_built_only_when_a_case_needs_it():
    T = Tables.from_parquet(default_table_path("copper_012mm"))
    m = squeeze_model(T, "critical_junction")
    m._trap = None
    squeeze_out(T, p0=np.exp(m.x_trap - 1.0) * E * np.array([0.5, 1.0]), E_star=E, R=R,
                eta=ETA, theory="critical_junction")
    assert m._trap is None  # no case above the trap pressure: nothing built
    df = squeeze_out(T, p0=np.exp(m.x_trap + 0.1) * E, E_star=E, R=R, eta=ETA,
                     theory="critical_junction")
    assert m._trap is not None and df["status"].iloc[0] == "trapped"
    # tables whose theory never traps get the empty record (serves nothing)
    avg = squeeze_model(T, "average")
    assert not math.isfinite(avg.x_trap)
    assert tpm.empty().rows.x_lo > tpm.empty().rows.x_hi


def test_tire_footprint_trapped_rows_agree_with_the_quadrature():
    T = Tables.from_parquet(default_table_path("asphalt_024mm"))
    m = squeeze_model(T, "emt")
    m._trap = None
    p0 = np.exp(m.x_trap + np.array([0.05, 0.5])) * E
    kw = dict(p0=p0, E_star=E, R=R, eta=ETA, speed=20.0, footprint_length=0.1, theory="emt")
    f = tire_footprint(T, method="fast", **kw)
    assert m._trap is not None  # the fast path built the trapped side and took it
    q = tire_footprint(T, method="quad", **kw)
    assert list(f["status"]) == ["trapped", "trapped"] == list(q["status"])
    for col in ("u_exit", "u_inf", "u_trap"):
        np.testing.assert_allclose(f[col], q[col], rtol=1e-6)


def test_measured_interpolation_error_below_tolerance():
    T = Tables.from_parquet(default_table_path("pmma_34um"))
    m = squeeze_model(T, "critical_junction")
    tp, info = tpm.build(m, check=True)
    assert info["z_split"] > tpm.Z_LO_TRAP and info["max_rel_err_T"] < 1e-6, info


@pytest.mark.parametrize("piece_name", ["lo", "hi"])
def test_measured_error_sees_a_perturbed_table(piece_name):
    # the check is not the build's own arithmetic echoed back: ln T (upper piece) or T (lower)
    # moved by 1e-5 relative at one z node of every row shows up at the neighbouring cell
    # centres (the quintic's weight of a node value there is 1/2: ~5e-6)
    T = Tables.from_parquet(default_table_path("pmma_34um"))
    m = squeeze_model(T, "critical_junction")
    tp, _ = tpm.build(m, check=False)
    pr = getattr(tp, piece_name)
    C = pr.C.copy()
    k = C.shape[1] // 2
    if piece_name == "hi":
        C[:, k, 0] += 1e-5
    else:
        C[:, k, 0] *= 1.0 + 1e-5
    bad = tp._replace(**{piece_name: tpm.piece(pr.xn, pr.z0, pr.dz, C, pr.v_ext, pr.c, pr.d)})
    err = tpm.measure_error(m, bad)["max_rel_err_T"]
    assert 2e-6 < err < 2e-5, err


def test_stored_with_the_primitive_cache_and_read_back(tmp_path):
    from fastcontact.squeeze import _trap_store, set_primitive_cache

    T = Tables.from_parquet(default_table_path("copper_012mm"))
    set_primitive_cache(T, tmp_path)
    m = squeeze_model(T, "emt")
    tp, info = _trap_store.load_or_build(m)
    path = _trap_store.trap_path(tmp_path, m)
    assert path.is_file() and info["max_rel_err_T"] < 1e-6  # measured when it is stored
    back, info2 = _trap_store.read(path, expect_key=m.key())
    assert info2 == info
    for a, b in zip(tp, back):
        for fa, fb in zip(a, b):
            if isinstance(fa, np.ndarray):
                assert fa.dtype == fb.dtype and np.array_equal(fa, fb)
            else:
                assert fa == fb
    kw = dict(p0=np.exp(m.x_trap + np.array([0.01, 0.4])) * E, E_star=E, R=R, eta=ETA,
              theory="emt", times=(1e-3,))
    m._trap = None
    a = squeeze_out(T, **kw)  # reads the file
    assert m.trap_primitive_info == info
    m._trap = None
    path.write_bytes(b"not parquet")  # damaged: rebuilt and overwritten
    b = squeeze_out(T, **kw)
    _trap_store.read(path, expect_key=m.key())
    for col in a.columns:
        assert a[col].equals(b[col]), col
    with pytest.raises(ValueError, match="does not belong"):
        _trap_store.read(path, expect_key="other")


@pytest.mark.parametrize("name", ["asphalt_024mm", "pmma_34um"])
def test_rows_next_to_the_trap_pressure_cross_the_last_open_node_exactly(name):
    # non-trapped rows just below the trap pressure (the per-case quadrature's band) whose
    # film crosses the tables' last open node on its way to ū∞: t* against the independent
    # quadrature with panels broken at the tables' nodes (before the quadrature broke its own
    # panels there, 2026-12-03: off by up to 4.5e-3; now ~1e-10)
    from reference.trapped_reference import _gl_sum

    T = Tables.from_parquet(default_table_path(name))
    gx, gw = np.polynomial.legendre.leggauss(12)
    for theory in ("critical_junction", "emt"):
        m = squeeze_model(T, theory)
        v_kink = math.exp(float(m.tab.lnu[int(m.tab.n_open) - 1]))
        for dx in (-0.017, -0.001):
            x0 = m.x_trap + dx
            df = squeeze_out(T, p0=math.exp(x0) * E, E_star=E, R=R, eta=ETA, theory=theory)
            assert df["status"].iloc[0] == "ok"
            vinf, vs = df["u_inf"].iloc[0] / m.h_rms, df["u_start"].iloc[0] / m.h_rms
            assert vinf < v_kink < vs  # the film crosses the kink
            v = np.exp(np.asarray(m.tab.lnu, dtype=np.float64))
            v = np.sort(np.append(v, m.mp.v_top))
            br = np.ascontiguousarray(np.log(v[v > vinf * (1 + 1e-12)] - vinf))
            wa, wb = math.log(0.01 * vinf), math.log(vs - vinf)
            r1, r2 = (_gl_sum(m.tab, m.mp, x0, vinf, wa, wb, br, w, gx, gw) for w in (0.05, 0.025))
            assert abs(r1 / r2 - 1.0) < 1e-12
            got = df["t_star"].iloc[0] / df["tau0"].iloc[0]
            assert abs(got / r2 - 1.0) < TOL, (theory, dx, got, r2)


def test_barus_quadrature_next_to_the_trap_pressure_crosses_the_last_open_node_exactly():
    # the Barus engine's per-case quadrature (rows within 4.4 % below the trap pressure) breaks
    # its panels at the tables' last open node as the constant-viscosity one does: with a
    # negligible α (α p0 = 1e-12, a relative change ~1e-12 of the time) its t* agrees with the
    # constant-viscosity quadrature's, which the test above checks against the reference
    T = Tables.from_parquet(default_table_path("asphalt_024mm"))
    for theory in ("critical_junction", "emt"):
        m = squeeze_model(T, theory)
        p0 = math.exp(m.x_trap - 0.017) * E
        base = squeeze_out(T, p0=p0, E_star=E, R=R, eta=ETA, theory=theory, method="quad")
        bar = squeeze_out(T, p0=p0, E_star=E, R=R, eta=ETA, theory=theory, method="quad",
                          alpha_pv=1e-12 / p0)
        assert abs(bar["t_star"].iloc[0] / base["t_star"].iloc[0] - 1.0) < 1e-9


def test_time_continuous_and_monotone_across_the_split():
    # the two pieces meet at z_split: T from either side agrees there to rounding, so a start
    # just above it and a target just below give a time >= 0 (and the inverse is monotone)
    from numba import njit

    T = Tables.from_parquet(default_table_path("asphalt_024mm"))
    m = squeeze_model(T, "emt")
    lo, hi, tr = m.trap_primitive()
    assert tr.z_split > tpm.Z_LO_TRAP  # this table has the kink

    @njit
    def probe(lo, hi, tr, xs, eps):
        out = np.empty((xs.size, 4))
        vb = math.exp(tr.lnvb)
        for i in range(xs.size):
            st = tpm.trap_stencil(lo, tr, xs[i])
            a = tpm.trap_t(lo, hi, tr, st, vb, tr.z_split - eps)
            b = tpm.trap_t(lo, hi, tr, st, vb, tr.z_split)
            c = tpm.trap_t(lo, hi, tr, st, vb, tr.z_split + eps)
            out[i, 0], out[i, 1], out[i, 2] = a, b, c
            out[i, 3] = tpm.trap_z(lo, hi, tr, st, vb, 0.5 * (a + b))
        return out

    xs = tr.x_trap + np.exp(np.linspace(math.log(1.1e-8), math.log(tr.x_hi - tr.x_trap) - 1e-9,
                                        4001))
    for eps in (1e-12, 1e-9, 1e-6):
        r = probe(lo, hi, tr, xs, eps)
        assert np.all(r[:, 0] >= r[:, 1]) and np.all(r[:, 1] >= r[:, 2])
        assert np.all(np.abs(r[:, 0] / r[:, 1] - 1.0) < 30.0 * eps + 1e-13)  # h/T <= ~20
        assert np.all((r[:, 3] >= tr.z_split - eps) & (r[:, 3] <= tr.z_split))


@pytest.mark.parametrize("theory", ["critical_junction", "emt"])
def test_history_of_a_trapped_case_from_the_primitive(theory):
    # squeeze_history of a case above the trap pressure: served by the trapped side's primitive
    # (it was the per-case quadrature, one forward integration per call); ū at each time
    # against the independent reference (the forward time from the start to the returned ū),
    # and equal to squeeze_out's ū at the same times
    from fastcontact.squeeze import squeeze_history

    T = Tables.from_parquet(default_table_path("asphalt_024mm"))
    m = squeeze_model(T, theory)
    ref = TrappedReference(m)
    h, vb = m.h_rms, m.mp.v_trap
    x0 = m.x_trap + 0.2
    vs = 25.0 * vb
    p0 = math.exp(x0) * E
    t = np.concatenate([[0.0, math.inf], np.geomspace(1e-9, 1e3, 40)])[::-1]  # any order
    hist = squeeze_history(T, p0, E, R, ETA, theory, t=t, u_start=vs * h)
    assert hist.attrs["trapped"] and m._trap is not None
    tau = hist.attrs["tau0"]
    u = hist["u"].to_numpy() / h
    assert u[t == 0.0][0] == vs and u[t == math.inf][0] == vb
    df = squeeze_out(T, p0=p0, E_star=E, R=R, eta=ETA, theory=theory, u_start=vs * h,
                     ratios=(), times=tuple(t))
    np.testing.assert_array_equal(hist["u"].to_numpy(),
                                  [df[column_name("u_at", tk)].iloc[0] for tk in t])
    served = 0
    for tk, uk in zip(t, u):
        if not (0.0 < tk < math.inf) or uk - vb < 1e-8 * vb or uk == vs:
            continue
        t_red = tk / tau
        dt = ref.time(x0, vs, uk) - t_red
        sig, d = qk.state_gap(m.tab, m.mp, x0, vb, uk - vb)
        assert (abs(dt) < TOL * t_red
                or abs(dt) * sig * d < max(TOL * (uk - vb), 1e-8 * vb)), (tk, uk, dt)
        served += 1
    assert served >= 10
    # ū falls with t towards ū_trap
    order = np.argsort(t)
    assert np.all(np.diff(u[order]) <= 0.0)


def test_study_of_trapped_cases_only_builds_no_equilibrium_primitive():
    # every case above the equilibrium side's range (trapped, or next to the trap pressure):
    # the call builds only what it uses, and its rows are those of a call that had the
    # equilibrium side's primitive built (bit for bit: neither reads it)
    T = Tables.from_parquet(default_table_path("pmma_34um"))
    m = squeeze_model(T, "emt")
    m._prim = None
    x0 = m.x_trap + np.array([-0.01, 1e-9, 1e-3, 0.3])  # the band, the quadrature, trapped
    kw = dict(p0=np.exp(x0) * E, E_star=E, R=R, eta=ETA, theory="emt", times=(1e-3, 1.0))
    a = squeeze_out(T, **kw)
    assert m._prim is None and m._trap is not None
    assert list(a["status"]) == ["ok", "trapped", "trapped", "trapped"]
    tire = tire_footprint(T, p0=kw["p0"], E_star=E, R=R, eta=ETA, theory="emt", speed=20.0,
                          footprint_length=0.1, method="fast")
    assert m._prim is None
    m.primitive()
    b = squeeze_out(T, **kw)
    tire_b = tire_footprint(T, p0=kw["p0"], E_star=E, R=R, eta=ETA, theory="emt", speed=20.0,
                            footprint_length=0.1, method="fast")
    for x, y in ((a, b), (tire, tire_b)):
        for col in x.columns:
            assert x[col].equals(y[col]), col
    # one case inside the equilibrium side's range: built
    m._prim = None
    squeeze_out(T, **{**kw, "p0": np.exp(np.append(x0, m.x_trap - 1.0)) * E})
    assert m._prim is not None


@pytest.mark.parametrize("name", ["asphalt_072mm", "copper_012mm"])
def test_quadrature_of_trapped_rows_within_tolerance(name):
    # method="quad" (and the fast path's fall-back rows) on the trapped side with its default
    # panels: times to targets just above ū_trap against the independent reference. With unit
    # panels in ln(ū - ū_trap) these were up to 3.8e-6 off on these two tables (their last open
    # node lies below the trap pressure); a trapped row's panels are now a third of the width
    T = Tables.from_parquet(default_table_path(name))
    m = squeeze_model(T, "critical_junction")
    ref = TrappedReference(m)
    h, vb = m.h_rms, m.mp.v_trap
    x0 = m.x_trap + np.array([1.7e-4, 1.85e-4, 2.2e-4, 4.1e-4, 5.2e-4])
    vs = vb * np.array([30.0, 7.1, 3.7, 1.3, 89.0])
    df = squeeze_out(T, p0=np.exp(x0) * E, E_star=E, R=R, eta=ETA, theory="critical_junction",
                     u_start=vs * h, ratios=(1.5,), method="quad")
    assert (df["status"] == "trapped").all()
    checked = 0
    for i in range(x0.size):
        tau, vinf = df["tau0"].iloc[i], df["u_inf"].iloc[i] / h
        for col, r in (("t_star", 1.01), ("t_ratio_1.5", 1.5)):
            vt = r * vinf
            if vb < vt < vs[i]:
                got = df[col].iloc[i] / tau
                assert abs(got / ref.time(x0[i], vs[i], vt) - 1.0) < TOL, (col, x0[i], vs[i])
                checked += 1
    assert checked >= 5


@pytest.mark.parametrize("name", ["asphalt_072mm", "asphalt_024mm"])
def test_barus_trapped_rows_against_the_reynolds_reference(name):
    # a Barus oil (α = 1e-8 1/Pa) on trapped rows: times to targets just above ū_trap against
    # the independent Reynolds solution with η(p) (tests/reference/ext_reynolds.py, its
    # w-origin at ū_trap), and ū_trap at t = inf. The Barus engine integrated these rows in
    # ln(ū - ū∞), unresolved where σ̄ collapses at ū_trap: up to 17 % off (2026-12-04)
    from reference.ext_reynolds import squeeze_time

    T = Tables.from_parquet(default_table_path(name))
    m = squeeze_model(T, "critical_junction")
    h, vb, alpha = m.h_rms, m.mp.v_trap, 1e-8
    x0 = m.x_trap + np.array([2e-4, 0.05])
    p0 = np.exp(x0) * E
    vs = 5.0 * vb
    for i in range(x0.size):
        vinf = math.exp(qk._lnv_of_lnp(m.tab, m.mp, x0[i]))
        r = 1.05 * vb / vinf
        df = squeeze_out(T, p0=p0[i], E_star=E, R=R, eta=ETA, theory="critical_junction",
                         u_start=vs * h, ratios=(r,), times=(math.inf,), alpha_pv=alpha)
        assert df["status"].iloc[0] == "trapped"
        assert df[column_name("u_at", math.inf)].iloc[0] == pytest.approx(vb * h, rel=1e-12)
        got = df[column_name("t_ratio", r)].iloc[0]
        ref = squeeze_time(T, "critical_junction", p0[i], E, R, ETA, alpha, vs * h,
                           1.05 * vb * h, vb * h)
        assert abs(got / ref - 1.0) < TOL, (x0[i] - m.x_trap, got, ref)


@pytest.mark.parametrize("name", ["asphalt_072mm", "pmma_34um"])
def test_attrs_say_where_sigma_is_verified(name):
    """attrs["sigma_verified"] names the p/E* of the tables' last node whose σ̄ lies above the
    tables' σ̄ floor (read here from the table's own columns), below the trap pressure with
    the default floor; with a higher trap floor (1e-12) the trap pressure lies below it."""
    T = Tables.from_parquet(default_table_path(name))
    floor = float(T.info["sigma_floor"])
    p = np.asarray(T.data["p_over_E"], dtype=float)
    for theory in ("critical_junction", "emt"):
        sig = np.asarray(T.data[f"sigma_{theory}"], dtype=float)
        p_v = p[np.flatnonzero(sig > floor)[-1]]
        df = squeeze_out(T, p0=1e5, E_star=E, R=R, eta=ETA, theory=theory)
        text = df.attrs["sigma_verified"]
        assert f"p/E* = {p_v:.8g}" in text, (text, p_v)
        assert p_v < math.exp(squeeze_model(T, theory).x_trap)
        hi = squeeze_out(T, p0=1e5, E_star=E, R=R, eta=ETA, theory=theory, sigma_trap=1e-12)
        assert hi.attrs["sigma_verified"].endswith("up to the trap pressure")
    avg = squeeze_out(T, p0=1e5, E_star=E, R=R, eta=ETA, theory="average")
    assert avg.attrs["sigma_verified"].endswith("over the whole table")
