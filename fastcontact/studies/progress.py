"""A progress bar (tqdm) that appears only for work longer than ~2 s and keeps its clock
running while one long step (a first kernel compile, a table build) is under way.

The bar (and tqdm itself) is created only once the work has lasted ``delay`` seconds: a
quick run neither imports tqdm nor prints anything."""
from __future__ import annotations

import sys
import threading
import time

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
        self.total = total
        self.file = file or sys.stderr
        self.tty = bool(getattr(self.file, "isatty", lambda: False)())
        self.delay = delay
        self.bar = None
        self.n = 0
        self.desc = ""
        self._t0 = time.time()
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread = None

    def __enter__(self):
        if self.enabled and self.tty:     # a live clock on terminals only (no log spam)
            self._thread = threading.Thread(target=self._tick, daemon=True)
            self._thread.start()
        return self

    def _bar(self):
        """The tqdm bar once ``delay`` seconds have passed (created then), else None."""
        if self.bar is None and self.enabled and time.time() - self._t0 >= self.delay:
            with self._lock:
                if self.bar is None:
                    from tqdm import tqdm
                    bar = tqdm(total=self.total, initial=self.n, file=self.file, unit="step",
                               leave=False, dynamic_ncols=True, delay=self.delay,
                               mininterval=0.1 if self.tty else 10.0, desc=self.desc or None)
                    bar.start_t = self._t0            # the clock runs from the start of work
                    bar.refresh()                     # first drawn here, with that clock
                    self.bar = bar
        return self.bar

    def _tick(self):
        while not self._stop.wait(0.5):
            bar = self._bar()
            if bar is not None:
                with self._lock:
                    bar.refresh()

    def step(self, text):
        """Name the step now under way."""
        if self.enabled:
            self.desc = text
            bar = self._bar()
            if bar is not None:
                with self._lock:
                    bar.set_description_str(text, refresh=False)

    def advance(self, n=1):
        """Count ``n`` steps as done."""
        self._bar()                       # created now if due (initial = the steps done)
        with self._lock:
            self.n += n
            if self.bar is not None:
                self.bar.update(n)

    def __exit__(self, *exc):
        self._stop.set()
        if self._thread is not None:
            self._thread.join()
        if self.bar is not None:
            self.bar.close()
        return False
