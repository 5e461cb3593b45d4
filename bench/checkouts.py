"""Running one job script in a fresh process on a given checkout (A/B benches).

A bench that compares this checkout with a baseline (``git worktree`` of the commit before)
runs its job with ``PYTHONPATH`` on the checkout and its own numba cache, and reads the job's
last output line as JSON.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys


def run_job(job, src, cache, *args):
    """Run the Python source ``job`` with ``args`` in a fresh process that imports fastcontact
    from the checkout ``src`` and caches kernels in ``cache``; returns its last line as JSON."""
    env = dict(os.environ, PYTHONPATH=str(src), NUMBA_CACHE_DIR=str(cache))
    # cwd outside both checkouts: ``python -c`` puts the cwd first on sys.path
    out = subprocess.run([sys.executable, "-c", job, *args], env=env, check=True, cwd=cache.parent,
                         capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])
