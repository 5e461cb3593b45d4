"""The run summary's streamed statistics (studies.output.column_summary) against numpy on the
whole column held in memory."""
import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from fastcontact.studies.output import _Stats, column_summary


def _write(path, cols, row_group):
    table = pa.table(cols)
    pq.write_table(table, path, row_group_size=row_group)


def test_column_summary_matches_numpy_per_group(tmp_path):
    rng = np.random.default_rng(4)
    n = 50_000
    x = rng.lognormal(size=n)
    x[rng.integers(0, n, 300)] = np.nan
    x[rng.integers(0, n, 50)] = np.inf
    flag = rng.random(n) < 0.3
    path = tmp_path / "r.parquet"
    _write(path, {"x": x, "flag": flag, "name": np.array(["s"] * n)}, row_group=7_000)
    groups = [("a", 0, 12_345), ("b", 12_345, n)]  # boundaries inside row groups and batches
    got = column_summary(path, ["x", "flag", "name", "absent"], groups)
    for g, a, b in groups:
        (cx, kx, vx), (cf, kf, vf) = got[g]  # strings and absent columns are left out
        w = x[a:b][np.isfinite(x[a:b])]
        assert (cx, kx) == ("x", "num")
        assert vx == (w.min(), np.median(w), w.max())
        assert (cf, kf, vf) == ("flag", "bool", (int(flag[a:b].sum()), b - a))


def test_stats_sampled_median_is_an_even_sample():
    rng = np.random.default_rng(5)
    v = rng.normal(size=1003)
    st = _Stats(v.size, exact=100)  # step 11: every 11th value of the whole column
    for lo in range(0, v.size, 97):  # blocks that do not align with the step
        st.add_num(v[lo:lo + 97])
    lo_, med, hi = st.num()
    assert (lo_, hi) == (v.min(), v.max())
    assert med == np.median(v[::11])
