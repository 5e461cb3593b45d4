"""`fastcontact bem` command group, driven through its own argparse wiring (issue 13)."""
import argparse
import io

import pandas as pd
import pytest

from fastcontact.figures.validation_figures import comparison_figure
from fastcontact.validation import Calibration
from fastcontact.validation.cli import add_bem_commands
from fastcontact.validation.compare import read_reference


def _run(argv):
    p = argparse.ArgumentParser(prog="fastcontact")
    sub = p.add_subparsers(dest="command")
    add_bem_commands(sub, comparison_figure)  # as the main CLI hands it in
    a = p.parse_args(argv)
    out, err = io.StringIO(), io.StringIO()
    code = a.bem_func(a, out, err)
    return code, out.getvalue(), err.getvalue()


def test_reference_compare_calibrate(tmp_path):
    ref = tmp_path / "ref.parquet"
    code, out, _ = _run(["bem", "reference", "--hurst", "0.8", "--q1-factor", "8",
                         "--roll-factor", "2", "--E-star", "1e7", "--areas", "0.05,0.15,0.3,0.6",
                         "--n", "32", "--seeds", "0,1", "--no-progress", "-o", str(ref)])
    assert code == 0 and "flow stops at" in out
    df = read_reference(ref)
    assert df.attrs["E_star"] == 1e7 and len(df) == 4
    cal = tmp_path / "cal.toml"
    code, out, _ = _run(["bem", "calibrate", str(ref), "-o", str(cal)])
    assert code == 0 and "gamma" in out
    c = Calibration.from_toml(cal)
    assert set(c.fitted) == {"gamma", "alpha_cj", "a_perc", "emt_threshold"}
    table = tmp_path / "cmp.csv"
    code, out, _ = _run(["bem", "compare", str(ref), "--calibration", str(cal), "-o", str(table),
                         "--figure", str(tmp_path / "cmp.png")])
    assert code == 0
    t = pd.read_csv(table)
    assert set(t.label) == {"average", "critical_junction", "emt", "average+cal",
                            "critical_junction+cal", "emt+cal"}
    assert (tmp_path / "cmp.png").stat().st_size > 1000


def test_bad_arguments_exit():
    with pytest.raises(SystemExit):
        _run(["bem", "reference", "--E-star", "1e7", "--areas", "0.1", "-o", "x.parquet"])
    with pytest.raises(SystemExit):
        _run(["bem", "reference", "--hurst", "0.8", "--E-star", "1e7", "--areas", "a,b",
              "-o", "x.parquet"])
