"""The progress bar of long runs (issue 12 point 5): silent for quick work, a tqdm bar with the
step name once the work has lasted ``delay`` seconds."""
from __future__ import annotations

import io
import time

from fastcontact.studies.progress import Progress


def test_quick_work_prints_nothing_and_creates_no_bar():
    f = io.StringIO()
    with Progress(3, True, f, delay=5.0) as p:
        for k in range(3):
            p.step(f"step {k}")
            p.advance()
    assert f.getvalue() == "" and p.bar is None and p.n == 3


def test_slow_work_shows_a_bar_with_the_step_and_the_count():
    f = io.StringIO()
    with Progress(4, True, f, delay=0.05) as p:
        p.step("tables road")
        p.advance()
        time.sleep(0.1)                       # past the delay
        p.step("figure u_of_t")
        p.advance()
        assert p.bar is not None
        assert p.bar.n == 2 and p.bar.total == 4
        assert time.time() - p.bar.start_t >= 0.1       # the clock runs from the start
    text = f.getvalue()
    assert "figure u_of_t" in text and "/4" in text


def test_disabled_is_silent_even_when_slow():
    f = io.StringIO()
    with Progress(2, False, f, delay=0.0) as p:
        p.step("x")
        time.sleep(0.01)
        p.advance()
    assert f.getvalue() == "" and p.bar is None
