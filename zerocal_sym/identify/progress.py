"""Progress of a long run on stderr (:class:`Progress`): a tqdm bar on a terminal, else a line every 10 % (or
every ``every_pct``)."""
from __future__ import annotations

import sys
import time


class Progress:
    """Progress on stderr: a tqdm bar on a terminal; otherwise (a log, a pipe) a line every ``every_pct`` %.

    ``progress(done)`` with the number of ``unit`` done; ``enabled=False``
    (``--quiet``) prints nothing.  :meth:`close` ends the bar.
    """

    def __init__(self, total: int, label: str = "compare", stream=None, enabled: bool = True, unit: str = "trial",
                 every_pct: int = 10):
        self.total, self.label, self.enabled = max(1, int(total)), label, enabled
        self.stream = sys.stderr if stream is None else stream
        self.t0 = time.perf_counter()
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())
        self.unit, self.every_pct = unit, int(every_pct)
        self.next_pct = self.every_pct
        self._bar = None
        self._done = 0

    def __call__(self, done: int) -> None:
        if not self.enabled:
            return
        done = int(done)
        if self.tty:
            if self._bar is None:
                from tqdm import tqdm

                self._bar = tqdm(total=self.total, desc=self.label, file=self.stream, unit=self.unit,
                                 mininterval=0.2, dynamic_ncols=True, leave=True)
            self._bar.update(done - self._done)
            self._done = done
            if done >= self.total:
                self.close()
            return
        frac = done / self.total
        if 100 * frac >= self.next_pct or done == self.total:
            while self.next_pct <= 100 * frac:
                self.next_pct += self.every_pct
            el = time.perf_counter() - self.t0
            eta = el / frac - el if frac > 0 else float("nan")
            bar = "#" * int(30 * frac) + "." * (30 - int(30 * frac))
            self.stream.write(f"{self.label} [{bar}] {done}/{self.total}  {el:.1f} s, eta {eta:.0f} s\n")
            self.stream.flush()

    def close(self) -> None:
        if self._bar is not None:
            self._bar.close()
            self._bar = None
