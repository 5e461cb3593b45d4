"""The run figures (issue 12 point 7): every case drawn, small multiples per surface, trapped
cases with their ū_trap, one style for every figure."""
from __future__ import annotations

import numpy as np
import pytest

import fastcontact.figures.scene as fs
from fastcontact.studies.load import load_scene
from fastcontact.studies.run import run_scene


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory, monkeypatch):
    monkeypatch.setenv("FASTCONTACT_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "table_cache"))


@pytest.fixture
def captured(monkeypatch):
    figs = {}

    def save(fig, path, **kw):
        figs[path.name] = fig
        return path
    monkeypatch.setattr(fs, "save_png", save)
    return figs


def _curves(ax):
    """The ū(t) curves of a panel: solid, drawn with > 2 points (not the reference lines)."""
    return [ln for ln in ax.get_lines() if ln.get_linestyle() == "-" and len(ln.get_xdata()) > 2
            and ln.get_linewidth() in (1.0, 1.8) and ln.get_label() != "flat surfaces"]


def test_every_case_drawn_in_small_multiples(tmp_path, captured):
    sc = {"title": "many", "study": {"kind": "squeeze", "theory": "critical_junction",
                                     "p0": {"start": "0.1 MPa", "stop": "5 MPa", "num": 12,
                                            "log": True}},
          "surfaces": {"cu": {"table": "copper_012mm"}, "road": {"table": "asphalt_024mm"}},
          "material": {"E": "2.3 MPa", "nu": 0.5}, "fluid": {"eta": "1 mPa s"},
          "geometry": {"R": "1 cm"}, "outputs": {"figures": ["u_of_t", "t_star"]}}
    res = run_scene(load_scene(sc), tmp_path / "o", make_figures=fs.make_scene_figure)
    df = res.results
    fig = captured["squeeze_u_of_t.png"]
    panels = [ax for ax in fig.axes if ax.get_visible()]
    assert len(panels) == 2                                     # one panel per surface
    for ax, name in zip(panels, ["cu", "road"]):
        assert len(_curves(ax)) == (df.surface == name).sum() == 12   # no 8-curve cap
    trapped = df[(df.surface == "cu") & df.trapped]
    assert len(trapped) > 0
    cu = panels[0]
    texts = [t.get_text() for t in cu.texts]
    assert 1 <= sum("trapped" in t for t in texts) <= len(trapped)     # one per distinct level
    levels = [ln.get_ydata()[0] for ln in cu.get_lines() if ln.get_linestyle() == "-."
              and len(ln.get_xdata()) == 2 and ln.get_xdata()[0] == 0]
    assert np.allclose(sorted(levels), sorted(trapped.u_trap * 1e3), rtol=1e-9)
    # t* of trapped cases is infinite: marked, and said in the legend
    tfig = captured["squeeze_t_star.png"]
    labels = tfig.axes[0].get_legend_handles_labels()[1]
    assert any("trapped" in lab for lab in labels)
    assert tfig.texts[0].get_text() == fig.texts[0].get_text() == "many"   # one style


def test_many_cases_thinned_visibly(tmp_path, captured, monkeypatch):
    monkeypatch.setattr(fs, "MAX_CURVES_PER_PANEL", 5)
    sc = {"title": "thin", "study": {"kind": "squeeze", "p0": {"start": "0.1 MPa", "stop": "1 MPa",
                                                                "num": 9}},
          "surfaces": {"road": {"table": "asphalt_024mm"}},
          "material": {"E": "10 MPa", "nu": 0.5}, "fluid": {"eta": "1 mPa s"},
          "geometry": {"R": "2 cm"}, "outputs": {"figures": ["u_of_t"]}}
    run_scene(load_scene(sc), tmp_path / "o", make_figures=fs.make_scene_figure)
    ax = captured["squeeze_u_of_t.png"].axes[0]
    assert "(5 of 9 cases)" in ax.get_title()
    assert len(_curves(ax)) == 5
