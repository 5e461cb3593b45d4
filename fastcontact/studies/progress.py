"""A progress bar (tqdm) that appears only for work longer than ~2 s and keeps its clock
running while one long step (a first kernel compile, a table build) is under way."""
from __future__ import annotations

import sys
import threading

from tqdm import tqdm

__all__ = ["Progress"]


class Progress:
    """``with Progress(total, enabled, file) as p: p.step("what"); ...; p.advance()``.

    Parameters
    ----------
    total : int
        Number of steps.
    enabled : bool
        False: silent.
    file : file-like
        Where the bar is drawn (default stderr).
    delay : float
        Seconds [s] before the bar first appears.
    """

    def __init__(self, total, enabled=True, file=None, delay=2.0):
        self.enabled = bool(enabled)
        file = file or sys.stderr
        self.tty = bool(getattr(file, "isatty", lambda: False)())
        self.bar = tqdm(total=total, disable=not self.enabled, file=file, delay=delay,
                        unit="step", leave=False, dynamic_ncols=True,
                        mininterval=0.1 if self.tty else 10.0)
        self.delay = delay
        self._stop = threading.Event()
        self._thread = None

    def __enter__(self):
        if self.enabled and self.tty:     # a live clock on terminals only (no log spam)
            self._thread = threading.Thread(target=self._tick, daemon=True)
            self._thread.start()
        return self

    def _tick(self):
        while not self._stop.wait(0.5):
            if self.bar._time() - self.bar.start_t >= self.delay:
                self.bar.refresh()

    def step(self, text):
        """Name the step now under way."""
        if self.enabled:
            self.bar.set_description_str(text, refresh=False)

    def advance(self, n=1):
        """Count ``n`` steps as done."""
        self.bar.update(n)

    def __exit__(self, *exc):
        self._stop.set()
        if self._thread is not None:
            self._thread.join()
        self.bar.close()
        return False
