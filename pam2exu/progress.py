"""A one-line progress bar on stderr, shown only on an interactive terminal.

Long runs (the frames of an animation, the chunks of the native pass of a large run) report
their progress through ``Progress``. It writes only when its stream is a terminal
(``isatty()``), so CI logs, pipes, redirections and captured output get nothing; set
``PAM2EXU_PROGRESS=0`` to switch it off on a terminal too.

>>> with Progress(200, "frames") as bar:       # doctest: +SKIP
...     for k in range(200):
...         bar.update(k + 1)
"""
from __future__ import annotations

import os
import sys
import time

#: characters of the bar itself
WIDTH = 30


def interactive(stream) -> bool:
    """True when ``stream`` is a terminal and progress is not switched off."""
    if os.environ.get("PAM2EXU_PROGRESS", "1").strip().lower() in ("0", "no", "false", "off"):
        return False
    isatty = getattr(stream, "isatty", None)
    try:
        return bool(isatty and isatty())
    except (OSError, ValueError):            # a closed or detached stream
        return False


class Progress:
    """``label [#########.........]  42%`` on one line, redrawn when the percentage changes.

    Parameters
    ----------
    total : int
        Number of units of work (frames, chunks).
    label : str
        What is being done, a few words.
    stream : file, optional
        Where to write (default: ``sys.stderr`` at construction time).
    min_total : int
        Below this many units the bar stays silent (the work is over in a blink).
    rate : bool
        Also show the units done, their rate and the time left (``1,200/10,000 label
        35.2/s 0:04:10 left``), from the units done since the first update (a resumed study's
        earlier work does not count in its rate); redrawn at every update.
    clock : callable
        Seconds of a monotonic clock (``time.monotonic``; a test's own).

    The line is erased when the bar closes, so what is printed next starts clean.
    """

    def __init__(self, total: int, label: str, stream=None, min_total: int = 2,
                 rate: bool = False, clock=time.monotonic):
        self.stream = sys.stderr if stream is None else stream
        self.total = max(int(total), 0)
        self.label = label
        self.enabled = self.total >= min_total and interactive(self.stream)
        self.rate, self.clock = rate, clock
        self._first = None               # (time, done) of the first update
        self._shown = -1
        self._length = 0

    def update(self, done: int, total: int | None = None) -> None:
        """``done`` units of ``total`` (default: the total given at construction) are done.

        Accepts matplotlib's ``progress_callback(current_frame, total_frames)`` call.
        """
        if not self.enabled:
            return
        total = self.total if total is None or total <= 0 else total
        percent = min(100, max(0, int(100 * done / max(total, 1))))
        if percent == self._shown and not self.rate:
            return
        self._shown = percent
        filled = WIDTH * percent // 100
        line = f"{self.label} [{'#' * filled}{'.' * (WIDTH - filled)}] {percent:3d}%"
        if self.rate:
            line += self._rate(done, total)
        self._length = max(self._length, len(line))
        self._write("\r" + line.ljust(self._length))

    def _rate(self, done: int, total: int) -> str:
        """'  1,200/10,000 label  35.2/s  0:04:10 left' (rate and time once units were done)."""
        now = self.clock()
        if self._first is None:
            self._first = (now, done)
        text = f"  {done:,}/{total:,} {self.label}"
        seconds, units = now - self._first[0], done - self._first[1]
        if seconds > 0 and units > 0:
            speed = units / seconds
            left = int(round(max(total - done, 0) / speed))
            text += f"  {speed:.3g}/s  {left // 3600}:{left // 60 % 60:02d}:{left % 60:02d} left"
        return text

    def close(self) -> None:
        """Erase the bar's line."""
        if self.enabled and self._shown >= 0:
            self._write("\r" + " " * self._length + "\r")
        self.enabled = False

    def _write(self, text: str) -> None:
        try:
            self.stream.write(text)
            self.stream.flush()
        except (OSError, ValueError):        # the terminal went away: stop reporting
            self.enabled = False

    def __enter__(self) -> "Progress":
        self.update(0)
        return self

    def __exit__(self, *exc) -> None:
        self.close()
