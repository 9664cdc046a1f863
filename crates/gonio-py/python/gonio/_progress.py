"""The progress bar of ``Scene.render``: tqdm's notebook widget in Jupyter (when tqdm is installed), a
one-line text bar on stderr in a terminal, nothing otherwise (pipes, files, CI logs)."""

from __future__ import annotations

import sys
import time
from typing import Any, Optional, TextIO


def _in_notebook() -> bool:
    shell = sys.modules.get("IPython")
    if shell is None or "ipykernel" not in sys.modules:
        return False
    try:
        return type(shell.get_ipython()).__name__ == "ZMQInteractiveShell"  # type: ignore[attr-defined]
    except Exception:
        return False


def _duration(seconds: float) -> str:
    seconds = int(max(seconds, 0))
    h, rest = divmod(seconds, 3600)
    m, s = divmod(rest, 60)
    return f"{h}:{m:02d}:{s:02d}" if h else f"{m:02d}:{s:02d}"


def _count(n: float) -> str:
    for unit, scale in (("G", 1e9), ("M", 1e6), ("k", 1e3)):
        if n >= scale:
            return f"{n / scale:.1f}{unit}"
    return f"{n:.0f}"


class TextBar:
    """``desc  42%|████▏     | 1.2M/2.9M samples [00:03<00:04, 410.2k samples/s]`` redrawn in place."""

    def __init__(self, total: int, desc: str, stream: TextIO, width: int = 30, interval: float = 0.1) -> None:
        self.total, self.desc, self.stream, self.width, self.interval = max(total, 1), desc, stream, width, interval
        self.start = time.monotonic()
        self.last_draw = -1.0
        self.update(0)

    def line(self, done: int) -> str:
        frac = min(max(done / self.total, 0.0), 1.0)
        cells = frac * self.width
        full = int(cells)
        partial = " ▏▎▍▌▋▊▉"[int((cells - full) * 8)] if full < self.width else ""
        bar = ("█" * full + partial).ljust(self.width)
        elapsed = time.monotonic() - self.start
        rate = done / elapsed if elapsed > 0 else 0.0
        eta = (self.total - done) / rate if rate > 0 else 0.0
        return (
            f"{self.desc} {frac * 100:3.0f}%|{bar}| {_count(done)}/{_count(self.total)} samples "
            f"[{_duration(elapsed)}<{_duration(eta)}, {_count(rate)} samples/s]"
        )

    def update(self, done: int) -> None:
        now = time.monotonic()
        if now - self.last_draw < self.interval:
            return
        self.last_draw = now
        self.stream.write("\r" + self.line(done))
        self.stream.flush()

    def close(self, done: int) -> None:
        self.last_draw = -1.0
        self.update(done)
        self.stream.write("\n")
        self.stream.flush()


class NotebookBar:
    """tqdm's widget, fed with absolute counts."""

    def __init__(self, total: int, desc: str) -> None:
        from tqdm.auto import tqdm

        self.bar = tqdm(total=total, desc=desc, unit=" samples", unit_scale=True)
        self.done = 0

    def update(self, done: int) -> None:
        self.bar.update(done - self.done)
        self.done = done

    def close(self, done: int) -> None:
        self.update(done)
        self.bar.close()


def bar(total: int, desc: str, stream: Optional[TextIO] = None) -> Any:
    """A bar with ``update(done)`` and ``close(done)``, or ``None`` when there is nowhere to show one."""
    if stream is None and _in_notebook():
        try:
            return NotebookBar(total, desc)
        except ImportError:
            return None
    stream = stream if stream is not None else sys.stderr
    try:
        tty = stream is not None and stream.isatty()
    except (AttributeError, ValueError):
        tty = False
    return TextBar(total, desc, stream) if tty else None
