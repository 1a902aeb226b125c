"""Progress of a long loop on stderr: tqdm's bar on a terminal, plain lines otherwise.

A bar redraws itself with carriage returns, which merge into one long line when stderr is a
file or a pipe (``make demo > log.txt 2>&1``, a study run by a batch system). There
:func:`progress_bar` prints a plain line at the start and at each tenth of the work instead::

    superelement harmonics: 40 % (26/65 harmonic, 12 s)
"""
from __future__ import annotations

import sys
import time
from typing import Iterable, TextIO


def is_terminal(file: TextIO) -> bool:
    """Whether ``file`` is an interactive terminal (False for a file, a pipe or a closed stream)."""
    try:
        return bool(file.isatty())
    except (AttributeError, ValueError, OSError):
        return False


def progress_bar(total: int | None = None, desc: str = "", unit: str = "it", *, initial: int = 0,
                 leave: bool = True, iterable: Iterable | None = None, file: TextIO | None = None):
    """A progress reporter with tqdm's ``update(n)`` and ``close()`` (and iteration when ``iterable``
    is given): tqdm's bar when ``file`` (default stderr) is a terminal, else a :class:`PlainProgress`.

    Parameters
    ----------
    total : int, optional
        Units of work (default: ``len(iterable)``).
    desc, unit : str
        The label before the count and the name of one unit.
    initial : int
        Units already done (a resumed run).
    leave : bool
        Whether tqdm's bar stays on the terminal once closed (plain lines always stay).
    iterable : iterable, optional
        Iterate over the returned object to go through it, one update per item.
    file : text stream, optional
        Where to write; stderr by default.
    """
    file = sys.stderr if file is None else file
    if total is None and iterable is not None:
        total = len(iterable)
    if is_terminal(file):
        from tqdm import tqdm

        return tqdm(iterable, total=total, initial=initial, desc=desc, unit=unit, leave=leave, file=file)
    return PlainProgress(total, desc, unit, initial=initial, iterable=iterable, file=file)


class PlainProgress:
    """Progress as whole lines: one at the start, one as each tenth of ``total`` is passed, and one
    at :meth:`close` if the last count was not printed (an interrupted loop)."""

    def __init__(self, total: int | None, desc: str = "", unit: str = "it", *, initial: int = 0,
                 iterable: Iterable | None = None, file: TextIO | None = None, tenths: int = 10):
        self.total, self.desc, self.unit, self.n = total, desc, unit, initial
        self.iterable, self.file, self.tenths = iterable, sys.stderr if file is None else file, tenths
        self._start = time.perf_counter()
        self._printed = None
        self._closed = False
        self._line()

    def _fraction_step(self, n: int) -> int:
        return n * self.tenths // self.total if self.total else 0

    def _line(self) -> None:
        head = f"{self.desc}: " if self.desc else ""
        elapsed = f", {time.perf_counter() - self._start:.0f} s"
        if self.total:
            text = f"{head}{100 * self.n // self.total:3d} % ({self.n}/{self.total} {self.unit}{elapsed})"
        else:
            text = f"{head}{self.n} {self.unit}{elapsed}"
        print(text, file=self.file, flush=True)
        self._printed = self.n

    def update(self, n: int = 1) -> None:
        """``n`` more units done; a line when a new tenth of the total is reached."""
        before = self._fraction_step(self.n)
        self.n += n
        if self.total and self._fraction_step(self.n) > before:
            self._line()

    def close(self) -> None:
        """The last line, if its count was not printed yet."""
        if not self._closed:
            self._closed = True
            if self._printed != self.n:
                self._line()

    def __iter__(self):
        try:
            for item in self.iterable:
                yield item
                self.update(1)
        finally:
            self.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        self.close()
