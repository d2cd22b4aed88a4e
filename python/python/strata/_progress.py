"""Progress of one library call, shown where its user looks (used by the native module).

In a Jupyter kernel the status is one line of text in the running cell's output, updated in
place (an IPython display handle, as ``tqdm.auto`` does); on a terminal it is redrawn in place
on stderr; elsewhere (a pipe, a file) a line is printed every ``STRATA_LOG_INTERVAL`` seconds
(default 5). Log lines and warnings go to ``sys.stderr`` (the cell's stderr in Jupyter).
Each call has its own display: nothing here is process-global.
"""

from __future__ import annotations

import os
import sys
import time
from typing import Any, Optional


def in_notebook() -> bool:
    """True inside a Jupyter (IPython) kernel, as ``tqdm.auto`` decides."""
    ipython = sys.modules.get("IPython")
    if ipython is None:
        return False
    try:
        shell = ipython.get_ipython()
    except Exception:
        return False
    return shell is not None and "IPKernelApp" in getattr(shell, "config", {})


def _isatty(stream: Any) -> bool:
    try:
        return bool(stream.isatty())
    except Exception:
        return False


def auto() -> bool:
    """The default of ``progress=None``: shown in a notebook or on a terminal, not in batch."""
    return in_notebook() or _isatty(sys.stderr)


def _interval() -> float:
    try:
        return max(0.05, float(os.environ.get("STRATA_LOG_INTERVAL", "5")))
    except ValueError:
        return 5.0


class Display:
    """The display of one call: ``log(text, warning)`` for lines, ``update(status)`` for the
    running operation's status (``None``: none yet), ``close(completed)`` at the end.

    ``enabled`` shows progress and log lines (warnings are always shown); ``automatic``
    (``progress=None``) waits ``delay`` seconds before the first status, so that short calls
    print nothing.
    """

    def __init__(self, enabled: bool, automatic: bool = False, delay: float = 0.5):
        self.enabled = enabled
        self.delay = delay if automatic else 0.0
        self.t0 = time.monotonic()
        self.notebook = enabled and in_notebook()
        self.tty = enabled and not self.notebook and _isatty(sys.stderr)
        self.interval = _interval()
        self.last: Optional[str] = None
        self.last_line = -1e300
        self.handle: Any = None
        self.width = 0
        self.shown = False

    def log(self, text: str, warning: bool = False) -> None:
        if not (self.enabled or warning):
            return
        if self.tty and self.width:
            sys.stderr.write("\r" + " " * self.width + "\r")
            self.width = 0
        sys.stderr.write(text + "\n")
        sys.stderr.flush()

    def update(self, status: Optional[str]) -> None:
        if not self.enabled or status is None or status == self.last:
            return
        if time.monotonic() - self.t0 < self.delay:
            return
        now = time.monotonic()
        if not (self.notebook or self.tty) and now - self.last_line < self.interval:
            return
        self.last_line = now
        self._render(status)

    def _render(self, status: str) -> None:
        self.last = status
        self.shown = True
        if self.notebook:
            from IPython.display import display

            if self.handle is None:
                self.handle = display({"text/plain": status}, raw=True, display_id=True)
            else:
                self.handle.update({"text/plain": status}, raw=True)
        elif self.tty:
            sys.stderr.write("\r" + status.ljust(self.width))
            self.width = len(status)
            sys.stderr.flush()
        else:
            sys.stderr.write(status + "\n")
            sys.stderr.flush()

    def close(self, completed: bool, status: Optional[str]) -> None:
        """The call's end: its final ``status`` (``None``: it had no operation), marked
        done or interrupted, where a status was shown (or progress was asked explicitly)."""
        if self.enabled and status is not None and (self.shown or self.delay == 0.0):
            self._render(status + (" (done)" if completed else " (interrupted)"))
        if self.tty and self.width:
            sys.stderr.write("\n")
            sys.stderr.flush()
            self.width = 0
