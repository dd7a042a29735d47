"""One line on stderr while numba compiles the controller's equations (an empty JIT cache).

The kernels are compiled at their first call and kept in numba's cache (``cache=True``), so a
run on a machine (or in a fresh cache folder) that has not compiled them yet spends 10-20 s
compiling before it simulates.  ``compile_notice`` says so while it happens::

    ptint: compiling the controller's equations (once per machine) ... done in 13.9 s

numba reports a compilation (its ``numba:compile`` event) only on a cache miss: a kernel loaded
from the cache prints nothing.
"""

from __future__ import annotations

import sys
import time
from contextlib import contextmanager
from typing import Callable, Iterator, Optional, Sequence

from numba.core import event

MESSAGE = "ptint: compiling the controller's equations (once per machine) ..."


class CompileNotice(event.Listener):
    """A numba event listener: ``write(MESSAGE)`` at the first compilation of a function of
    ``modules`` (module name prefixes); ``seconds`` from then on."""

    def __init__(self, write: Callable[[str], object], modules: Sequence[str] = ("ptint_drake",)):
        self._write = write
        self._modules = tuple(modules)
        self.started: Optional[float] = None

    def on_start(self, ev) -> None:
        if self.started is not None:
            return
        module = getattr(getattr(ev.data.get("dispatcher"), "py_func", None), "__module__", None) or ""
        if module.startswith(self._modules):
            self.started = time.perf_counter()
            self._write(MESSAGE)

    def on_end(self, ev) -> None:
        pass

    @property
    def seconds(self) -> float:
        """Seconds since the first compilation (0 when nothing compiled)."""
        return 0.0 if self.started is None else time.perf_counter() - self.started


def _stderr(text: str) -> None:
    sys.stderr.write(text)
    sys.stderr.flush()


@contextmanager
def compile_notice(enabled: bool = True, write: Optional[Callable[[str], object]] = None,
                   modules: Sequence[str] = ("ptint_drake",)) -> Iterator[CompileNotice]:
    """While the block runs, ``MESSAGE`` once when a kernel of ``modules`` compiles, and at the
    end of the block `` done in X s`` and the end of the line (``write``: stderr by default).
    Nothing when every kernel comes from the cache or was compiled before, or not ``enabled``."""
    write = write or _stderr
    notice = CompileNotice(write, modules)
    if not enabled:
        yield notice
        return
    try:
        with event.install_listener("numba:compile", notice):
            yield notice
    except BaseException:
        if notice.started is not None:
            write("\n")  # the line ends before whatever reports the exception
        raise
    if notice.started is not None:
        write(f" done in {notice.seconds:.1f} s\n")
