"""Progress on stderr for everything that runs longer than a few seconds (stdout stays for results and
``--json``).

* :func:`bar`: a tqdm bar over a known number of items.
* :func:`stage`: one named stage of a longer job: a bar whose elapsed time keeps moving even while
  the work inside reports nothing (a ticker thread refreshes it), closed with a line giving the
  stage's real duration. :class:`Stages` numbers the stages of a job (``[2/5] E4 trim ...``).
* :func:`set_enabled`: the switch the command line's ``--quiet`` turns off, for every bar and stage at once;
  the command then also leaves out its closing ``done in`` line (:func:`done_line`).
"""

from __future__ import annotations

import contextlib
import sys
import threading
import time
from collections.abc import Iterator
from typing import Any

_ENABLED = True


def set_enabled(on: bool) -> None:
    """Show progress (bars, stages, the closing line) or not, for the whole process."""
    global _ENABLED
    _ENABLED = bool(on)


def enabled() -> bool:
    """Whether progress is shown (:func:`set_enabled`)."""
    return _ENABLED


def line(text: str) -> None:
    """One line on stderr, unless progress is off, that leaves a bar being drawn intact (through ``tqdm.write`` once
    a bar has been made, which clears the bar, prints the line and draws the bar again below it)."""
    if not _ENABLED:
        return
    if "tqdm" in sys.modules:
        from tqdm import tqdm

        tqdm.write(text, file=sys.stderr)
        sys.stderr.flush()
    else:
        print(text, file=sys.stderr, flush=True)


def done_line(what: str, seconds: float) -> None:
    """The closing line of a command on stderr, ``<what>: done in 12.3 s``, unless progress is off."""
    if _ENABLED:
        print(f"{what}: done in {duration_text(seconds)}", file=sys.stderr, flush=True)


class _Quiet:
    """The no-op stand-in for a bar when progress is off."""

    n = 0
    total = None

    def update(self, n: int = 1) -> None:
        self.n += n

    def set_postfix_str(self, s: str = "", refresh: bool = True) -> None:
        pass

    def set_postfix(self, *args: Any, **kwargs: Any) -> None:
        pass

    def close(self) -> None:
        pass


def bar(total: int | None, desc: str, enabled: bool = True, unit: str = "it", initial: int = 0,
        leave: bool = False) -> Any:
    """A tqdm bar on stderr (a no-op object when not ``enabled``, or when progress is off): every progress bar
    of the project is one of these, so all look alike and ``--quiet`` silences all. ``leave``: keep the bar's last
    state on screen when it closes (an evolution's: its best and mean)."""
    if not (enabled and _ENABLED):
        return _Quiet()
    from tqdm import tqdm

    fmt = "{desc} [{elapsed}]" if total is None else None
    return tqdm(total=total, desc=desc, unit=unit, file=sys.stderr, dynamic_ncols=True, leave=leave,
                mininterval=0.5 if sys.stderr.isatty() else 10.0, bar_format=fmt, initial=initial)


@contextlib.contextmanager
def stage(desc: str, total: int | None = None, enabled: bool = True, unit: str = "it") -> Iterator[Any]:
    """A named stage: a bar (of ``total`` items, or an elapsed-time counter) refreshed every second
    (every 10 s when stderr is not a terminal) while the block runs, then one line ``desc: 12.3 s``."""
    if not (enabled and _ENABLED):
        yield _Quiet()
        return
    b = bar(total, desc, True, unit)
    stop = threading.Event()
    period = 1.0 if sys.stderr.isatty() else 10.0

    def tick() -> None:
        while not stop.wait(period):
            try:
                b.refresh()
            except Exception:  # noqa: BLE001 - a closed stream must not kill the job
                return

    t = threading.Thread(target=tick, name="lifelike-mj-progress", daemon=True)
    t0 = time.perf_counter()
    t.start()
    ok = False
    try:
        yield b
        ok = True
    finally:
        stop.set()
        t.join()
        b.close()
        took = time.perf_counter() - t0
        print(f"{desc}: {'done in' if ok else 'stopped after'} {duration_text(took)}", file=sys.stderr, flush=True)


class Stages:
    """The numbered stages of one job: ``with stages.next("E4 trim"): ...`` prints ``[3/6] E4 trim``
    with a running bar, then its duration; :meth:`done` prints the job's total."""

    def __init__(self, job: str, count: int, enabled: bool = True) -> None:
        self.job, self.count, self.enabled = job, int(count), enabled
        self.i = 0
        self.t0 = time.perf_counter()

    def next(self, name: str, total: int | None = None, unit: str = "it") -> contextlib.AbstractContextManager:
        self.i += 1
        return stage(f"[{self.job} {self.i}/{self.count}] {name}", total, self.enabled, unit)

    def done(self, what: str) -> float:
        """Say what the job made (``[job] what``; the command's closing line gives the time) and return the
        job's duration (s)."""
        took = time.perf_counter() - self.t0
        if self.enabled and _ENABLED:
            print(f"[{self.job}] {what}", file=sys.stderr, flush=True)
        return took


def duration_text(s: float) -> str:
    """``12.3 s``, ``2 min 46 s`` or ``1 h 05 min``."""
    if s < 60:
        return f"{s:.1f} s"
    m, sec = divmod(int(round(s)), 60)
    return f"{m} min {sec:02d} s" if m < 60 else f"{m // 60} h {m % 60:02d} min"
