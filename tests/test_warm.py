"""``fastcontact compile`` (fastcontact.warm): kernels compiled ahead of a study are loaded, not
compiled again, by a later process; groups inferred from scenes; bad input in one line."""
import json
import os
import subprocess
import sys
import textwrap

import pytest

from fastcontact.cli import main
from fastcontact.studies.examples import example_scene_path
from fastcontact.studies.load import load_scene
from fastcontact.warm import GROUPS, scene_groups, warm

#: run in a fresh process: the group's own calls, with numba's compile events counted (a
#: kernel loaded from the disk cache raises none); a function defined here, which no cache
#: holds, shows that the listener sees a compile when there is one
_COUNT = textwrap.dedent("""
    import json, sys
    from numba import njit
    from numba.core import event
    names = []
    class L(event.Listener):
        def on_start(self, ev):
            names.append(ev.data["dispatcher"].py_func.__module__)
        def on_end(self, ev):
            pass
    event.register("numba:compile", L())
    from fastcontact.warm import warm_group
    warm_group(sys.argv[1])
    n_fc = sum(1 for m in names if m.startswith("fastcontact"))
    @njit
    def _probe(x):
        return x + 1
    _probe(1)
    print(json.dumps({"fastcontact": n_fc, "probe": names.count("__main__")}))
""")


def _env(cache):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache))
    env.pop("NUMBA_DISABLE_JIT", None)
    return env


def test_compiled_group_loads_without_compiling(tmp_path):
    """`fastcontact compile tables` into an empty cache; a new process running the same
    calls then compiles no fastcontact kernel (all loaded from the cache)."""
    cache = tmp_path / "numba"
    run = subprocess.run([sys.executable, "-m", "fastcontact", "compile", "tables"],
                         env=_env(cache), cwd=tmp_path, capture_output=True, text=True,
                         timeout=900)
    assert run.returncode == 0, run.stderr
    assert "compiled: tables" in run.stdout and str(cache) in run.stdout
    assert any(cache.rglob("*.nbi")), "nothing was written to the numba cache"
    after = subprocess.run([sys.executable, "-c", _COUNT, "tables"], env=_env(cache),
                           cwd=tmp_path, capture_output=True, text=True, timeout=900)
    assert after.returncode == 0, after.stderr
    counts = _last_json(after.stdout)
    assert counts["probe"] == 1      # the listener sees a compile
    assert counts["fastcontact"] == 0


def _last_json(text):
    return json.loads(text.strip().splitlines()[-1])


@pytest.mark.parametrize("name, groups", [("default", ["squeeze"]),
                                          ("tire_two_asphalts", ["tire"]),
                                          ("seal_pdms", ["seal"]),
                                          ("squeeze_copper", ["squeeze"])])
def test_scene_groups_of_the_shipped_scenes(name, groups):
    assert scene_groups(load_scene(example_scene_path(name))) == groups


def test_scene_groups_infer_tables_and_viscosity(tmp_path):
    scene = tmp_path / "s.toml"
    scene.write_text(textwrap.dedent("""
        [study]
        kind = "squeeze"
        theory = "emt"
        p0 = ["0.1 MPa", "0.2 MPa"]
        alpha_pv = ["0 1/Pa", "2 1/MPa"]
        [surfaces.s1]
        h_rms = "1 um"
        hurst = 0.8
        q0 = "1e4 1/m"
        q1 = "1e6 1/m"
        [material]
        E = "10 MPa"
        nu = 0.5
        [fluid]
        eta = "1 mPa s"
        [geometry]
        R = "1 cm"
    """))
    assert scene_groups(load_scene(scene)) == ["tables", "squeeze", "viscosity"]
    # alpha_pv = 0 only: the base engine, nothing more
    scene.write_text(scene.read_text().replace('["0 1/Pa", "2 1/MPa"]', '"0 1/Pa"'))
    assert scene_groups(load_scene(scene)) == ["tables", "squeeze"]


def test_study_sized_seal_calls_reach_the_o_ring_tables(monkeypatch):
    """The seal and viscosity groups' study-sized O-ring calls (``_seal_tables``) read their
    rows from the verified tables (and so compile those kernels, which a few rows never
    reach): p_b > 0, one Barus oil per row, one Roelands fluid's ψ_a from one ψ table."""
    import numpy as np

    from fastcontact import warm as warm_mod
    from fastcontact.defaults import load_default_tables
    from fastcontact.seal import hertz, viscosity

    read = []

    def spy(name, fn):
        def wrapped(*args, **kwargs):
            out = fn(*args, **kwargs)
            read.append((name, out is not None and bool(np.isfinite(out).any())))
            return out
        return wrapped
    monkeypatch.setattr(hertz, "table_W_pb", spy("pb", hertz.table_W_pb))
    monkeypatch.setattr(hertz, "table_W_beta", spy("beta", hertz.table_W_beta))
    monkeypatch.setattr(viscosity, "psi_drops_one_law",
                        spy("psi", viscosity.psi_drops_one_law))
    T = load_default_tables("asphalt_024mm")
    warm_mod._seal_tables(T)
    assert ("pb", True) in read
    read.clear()
    warm_mod._seal_tables(T, alpha_pv=lambda n: np.linspace(1e-7, 3e-6, n))
    assert ("beta", True) in read
    read.clear()
    warm_mod._seal_tables(T, viscosity="roelands", alpha_pv=2e-7, roelands_z=0.6,
                          roelands_p_r=1.96e8)
    assert any(name == "psi" for name, _ in read)


def test_bad_input_names_the_parameter(capsys):
    assert main(["compile", "tyre"]) == 2
    err = capsys.readouterr().err
    assert "'tyre'" in err and "squeeze" in err and len(err.strip().splitlines()) == 1
    with pytest.raises(ValueError, match="jobs = 0 is invalid"):
        warm(["tables"], jobs=0)
    with pytest.raises(ValueError, match="'tyre' is not one of"):
        warm(["tyre"])
    assert set(GROUPS) == {"tables", "squeeze", "tire", "seal", "viscosity"}
