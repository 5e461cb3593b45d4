"""O-rings with an outlet pressure p_b > 0 from the verified table of W(π_H, π_a, π_b).

``fastcontact/seal/hertz.py`` (:func:`~fastcontact.seal.hertz.table_W_pb`): ln W on a grid in
(ln π_H, y, z), z = y(π_b)/y(π_a), built line by line for the rows of a call, every cell
verified at its centre against the solver before use; unverified cells are solved.

References: the per-row solver (``solver=dict(table=False)``; Barus: ``TABLE_MIN_ROWS``
raised so that every row is solved) for many rows, and for a handful of table rows the
adaptive DOP853 shooting of the Reynolds equation in the fluid pressure itself
(``tests/reference/ext_reynolds.py``: dp_f/dθ = -q a sin θ e^{α(p_f - p_b)}/σ_eff(p_H sin θ -
p_f), p_f = p_a at the inlet end of the sealing zone, p_b at its outlet end; σ_eff from
``Tables.conductivity``), independent of the engine's panel solver and of its table.
"""
from __future__ import annotations

import math
import os
import sys

import numpy as np
import pytest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from reference.ext_reynolds import hertz_shoot  # noqa: E402

import fastcontact as fc  # noqa: E402
import fastcontact.seal.hertz as sh  # noqa: E402
import fastcontact.seal.viscosity as sv  # noqa: E402
from fastcontact.seal.context import seal_context  # noqa: E402

E_STAR, ETA, L_Y, R = 1e7, 1e-3, 0.1, 2e-3
ALPHA = 4e-6                         # Barus α [1/Pa]: α p_H up to 2 on these O-rings
#: Q from the table against the per-row solver and against the shooting reference (the
#: table's cells are verified to VERIFY_TOL = 2e-7 in ln W against the tight solver)
RTOL = 1e-6
SURFACE = dict(h_rms=5e-6, hurst=0.8, q0=1e4, q1=1e8)


@pytest.fixture(scope="module")
def tables():
    return fc.precompute(fc.SelfAffinePSD(**SURFACE), theories=("critical_junction",))


def _orings(n, seed, designs):
    """n O-rings of radius R in ``designs`` groups sharing p_H (p_H/E* log-uniform in
    [1e-3, 0.05]); Δp/p_H uniform in [1e-3, 0.99] and p_b/p_a uniform in [0, 0.99] per row,
    the rows past lift-off (p_a > p_H) drawn again. Returns the seal_leak keywords."""
    rng = np.random.default_rng(seed)
    lp = rng.uniform(math.log(1e-3), math.log(0.05), designs)
    pH = np.exp(np.repeat(lp, -(-n // designs))[:n]) * E_STAR
    dp = np.empty(n)
    s = np.empty(n)
    todo = np.arange(n)
    while todo.size:
        dp[todo] = rng.uniform(1e-3, 0.99, todo.size) * pH[todo]
        s[todo] = rng.uniform(0.0, 0.99, todo.size)
        todo = todo[dp[todo] / (1.0 - s[todo]) > pH[todo]]
    p_b = s / (1.0 - s) * dp                               # p_b/p_a = s
    a = 2.0 * R * pH / E_STAR                              # Hertz line contact: p_H = E* a/(2R)
    return dict(profile="hertz", R=R, f_N=math.pi * a * pH / 2.0, dp=dp, p_b=p_b, L_y=L_Y,
                E_star=E_STAR, eta=ETA)


def _row_args(kw):
    """(π_H, π_a, π_b, rows) of the O-rings ``kw`` for the table functions."""
    pa = kw["p_b"] + kw["dp"]
    pH = np.broadcast_to(fc.hertz_contact(R, kw["f_N"], E_STAR)[1], pa.shape).copy()
    return pH / E_STAR, pa / E_STAR, kw["p_b"] / E_STAR, np.flatnonzero(pa < pH)


def _spy_table_pb(monkeypatch):
    """The calls of :func:`~fastcontact.seal.hertz.table_W_pb` from now on, recorded as
    (α̃, Roelands law, rows it served — None where it was not read: not worth completing —,
    rows asked)."""
    calls = []
    real = sh.table_W_pb

    def spy(sc, piH, pia, pib, rows, al=0.0, vis=None, max_solves=None):
        W = real(sc, piH, pia, pib, rows, al, vis, max_solves)
        calls.append((al, vis, None if W is None else int(np.isfinite(W[rows]).sum()),
                      rows.size))
        return W

    monkeypatch.setattr(sh, "table_W_pb", spy)
    return calls


def _check_piezo_against_solver(tables, kw, got, min_ok, monkeypatch):
    """``got`` (a Barus/Roelands call of ``kw``) against the per-row solver (TABLE_MIN_ROWS
    raised: every row solved): the same statuses, more than ``min_ok`` rows "ok", their Q
    within RTOL."""
    with monkeypatch.context() as m:
        m.setattr(sv, "TABLE_MIN_ROWS", 10 ** 12)
        ref = fc.seal_leak(tables, **kw)
    assert list(got.status) == list(ref.status)
    ok = (ref.status == "ok").to_numpy()
    assert ok.sum() > min_ok
    assert _rel(got.Q[ok], ref.Q[ok]).max() <= RTOL


def _rel(a, b):
    return np.abs(np.asarray(a) / np.asarray(b) - 1.0)


def test_base_table_against_the_solver(tables):
    """4 O-ring designs (p_H/E* log-uniform in [1e-3, 0.05]), 4,000 rows with p_b > 0: a call
    that would need more solves for the table than its rows does not build it (the solver's
    numbers exactly); once built for these rows (kept), Q from the table within 1e-6 of the
    per-row solver on every row it serves, which are most rows; the same statuses; the rows
    it does not serve are the solver's exactly."""
    kw = _orings(4000, 11, designs=4)
    ref = fc.seal_leak(tables, **kw, solver=dict(table=False))
    sc = seal_context(tables, "critical_junction")
    before = fc.seal_leak(tables, **kw)
    assert not sh.hertz_pb_table(sc).rec.built.any()               # not worth a table
    np.testing.assert_array_equal(before.Q, ref.Q)
    piH, pia, pib, rows = _row_args(kw)
    assert sh.table_W_pb(sc, piH, pia, pib, rows) is not None      # built, no solve budget
    got = fc.seal_leak(tables, **kw)
    assert list(got.status) == list(ref.status)
    ok = (ref.status == "ok").to_numpy()
    assert ok.sum() > 3900 and np.all(kw["p_b"] > 0)
    tab = ok & (got.error_estimate == sh.VERIFY_TOL).to_numpy()  # rows read from the table
    assert tab.sum() > 0.95 * ok.sum(), tab.sum()
    assert _rel(got.Q[tab], ref.Q[tab]).max() <= RTOL
    np.testing.assert_array_equal(got.Q[ok & ~tab], ref.Q[ok & ~tab])


def test_base_table_next_to_its_edges(tables):
    """Rows at the table's z = 1 edge (dp → 0: p_b/p_a = 1 - 1e-9, the linear-response limit,
    as the p_b = 0 table's y = 0 edge) and next to the outlet lift-off (p_a and p_b within
    1e-4 of p_H), on a table built for them: within 1e-6 of the solver, from the table or,
    where its cells are not verified, the solver's exactly; the dp → 0 rows from the table."""
    pH = 0.01 * E_STAR
    f_N = math.pi * (2.0 * R * pH / E_STAR) * pH / 2.0
    ra = np.concatenate((np.geomspace(1e-3, 0.9, 40), 1.0 - np.geomspace(1e-4, 1e-6, 10)))
    s = np.concatenate((np.full(40, 1.0 - 1e-9), np.full(10, 0.9999)))
    pa = ra * pH
    kw = dict(profile="hertz", R=R, f_N=f_N, dp=pa * (1.0 - s), p_b=pa * s, L_y=L_Y,
              E_star=E_STAR, eta=ETA)
    sc = seal_context(tables, "critical_junction")
    piH, pia, pib, rows = _row_args(kw)
    W = sh.table_W_pb(sc, piH, pia, pib, rows)
    assert np.isfinite(W[:40]).all()                               # dp → 0: from the table
    got = fc.seal_leak(tables, **kw)
    ref = fc.seal_leak(tables, **kw, solver=dict(table=False))
    assert (ref.status == "ok").all() and list(got.status) == list(ref.status)
    assert _rel(got.Q, ref.Q).max() <= RTOL
    solved = ~np.isfinite(W)
    np.testing.assert_array_equal(got.Q[solved], ref.Q[solved])


def test_barus_table_against_the_solver(tables, monkeypatch):
    """A Barus fluid (α = 4e-6 1/Pa), 3 O-ring designs, 3,000 rows with p_b > 0: the p_b > 0
    table of that fluid (keyed α̃ = α E*, not the base table) serves most rows, Q within 1e-6
    of the per-row solver, the same statuses."""
    kw = dict(_orings(3000, 12, designs=3), alpha_pv=ALPHA)
    sc = seal_context(tables, "critical_junction")
    piH, pia, pib, rows = _row_args(kw)
    assert sh.table_W_pb(sc, piH, pia, pib, rows, ALPHA * E_STAR) is not None   # built
    assert sh.hertz_pb_table(sc, ALPHA * E_STAR) is not sh.hertz_pb_table(sc)
    calls = _spy_table_pb(monkeypatch)
    got = fc.seal_leak(tables, **kw)
    assert len(calls) == 1 and calls[0][0] == ALPHA * E_STAR and calls[0][1] is None
    assert calls[0][2] is not None and calls[0][2] > 0.95 * calls[0][3], calls
    _check_piezo_against_solver(tables, kw, got, 2900, monkeypatch)


@pytest.mark.parametrize("alpha", [0.0, ALPHA])
def test_table_rows_against_shooting_reference(tables, alpha):
    """A handful of p_b > 0 rows read from the table (base and Barus) against the adaptive
    DOP853 shooting of the Reynolds equation in p_f (reference module docstring): within
    1e-6 (the table within 2e-7 of the tight solver, the shooting within ~1e-10)."""
    pH = np.array([2e-3, 2e-3, 1e-2, 1e-2, 3e-2]) * E_STAR
    pa = np.array([0.3, 0.9, 0.05, 0.7, 0.5]) * pH
    pb = np.array([0.5, 0.2, 0.9, 0.95, 0.3]) * pa
    a = 2.0 * R * pH / E_STAR
    kw = dict(profile="hertz", R=R, f_N=math.pi * a * pH / 2.0, dp=pa - pb, p_b=pb, L_y=L_Y,
              E_star=E_STAR, eta=ETA, alpha_pv=alpha)
    sc = seal_context(tables, "critical_junction")
    al = alpha * E_STAR
    piH, pia, pib, rows = _row_args(kw)
    W = sh.table_W_pb(sc, piH, pia, pib, rows, al)                  # built for these rows
    assert np.isfinite(W).all()                                     # all from the table
    if alpha > 0.0:
        with pytest.MonkeyPatch.context() as m:                     # 5 rows: the table read
            m.setattr(sv, "TABLE_MIN_ROWS", 1)
            got = fc.seal_leak(tables, **kw)
    else:
        got = fc.seal_leak(tables, **kw)
        assert (got.error_estimate == sh.VERIFY_TOL).all()
    plo = tables.p_range[0] * E_STAR

    def sigma(pc):
        return tables.conductivity(np.maximum(pc, plo * (1 + 1e-7)), E_STAR, ETA,
                                   "critical_junction")

    for i in range(pH.size):
        q = hertz_shoot(sigma, pH[i], a[i], pa[i], pb[i], alpha) * L_Y
        assert abs(got.Q[i] / q - 1.0) <= RTOL, (i, got.Q[i], q)


@pytest.mark.parametrize("alpha", [0.0, ALPHA])
def test_p_b_zero_rows_unchanged(tables, alpha, monkeypatch):
    """Rows with p_b = 0 in a call mixed with p_b > 0 rows (whose table is read) keep the p_b = 0
    table's numbers bit for bit: on the rows that table serves, the same as a call of those
    rows alone (base: error_estimate = VERIFY_TOL, read from that table; the rows it does not
    serve are solved, Barus ones in chains whose length depends on the rows solved)."""
    monkeypatch.setattr(sv, "TABLE_MIN_ROWS", 50)
    kw = _orings(600, 13, designs=2)
    zero = np.arange(600) % 3 == 0
    kw["p_b"] = np.where(zero, 0.0, kw["p_b"])
    kw["alpha_pv"] = alpha
    sc = seal_context(tables, "critical_junction")
    piH, pia, pib, rows = _row_args(kw)
    assert sh.table_W_pb(sc, piH, pia, pib, rows[~zero[rows]], alpha * E_STAR) is not None
    W0 = sh.table_W(sc, piH, pia, rows[zero[rows]], alpha * E_STAR)  # p_b = 0: its table
    at0 = np.isfinite(W0[zero])
    assert at0.mean() > 0.95
    alone = {k: (v[zero] if isinstance(v, np.ndarray) else v) for k, v in kw.items()}
    only = fc.seal_leak(tables, **alone)
    mixed = fc.seal_leak(tables, **kw)
    np.testing.assert_array_equal(mixed.Q[zero][at0], only.Q[at0])
    if alpha == 0.0:
        assert (only.error_estimate == sh.VERIFY_TOL).mean() > 0.95
        assert (mixed.error_estimate[~zero] == sh.VERIFY_TOL).mean() > 0.95


def test_roelands_table_built_by_a_large_call(tables, monkeypatch):
    """A Roelands fluid (Z = 0.6, p_r = 2e5 Pa), one O-ring design, 24,000 rows with p_b > 0: a
    call with enough rows builds the fluid's p_b > 0 table itself (keyed by its law, no
    solve budget exceeded) and reads most rows from it; Q within 1e-6 of the per-row solver,
    the same statuses."""
    kw = dict(_orings(24000, 14, designs=1), alpha_pv=4e-6, viscosity="roelands",
              roelands_z=0.6, roelands_p_r=2e5)
    calls = _spy_table_pb(monkeypatch)
    got = fc.seal_leak(tables, **kw)
    assert len(calls) == 1 and calls[0][1] is not None and calls[0][1][1] == 0.6
    assert calls[0][2] is not None and calls[0][2] > 0.95 * calls[0][3], calls
    _check_piezo_against_solver(tables, kw, got, 23000, monkeypatch)
