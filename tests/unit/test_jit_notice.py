"""The compile notice (controllers.ptsmc.jit_notice): one line while a kernel of the package compiles, and
its time once done; nothing when the kernel was compiled (or loaded from the cache) before."""

from __future__ import annotations

import numba

from ptint_drake.controllers.ptsmc.jit_notice import MESSAGE, compile_notice


def _kernel(module: str):
    def add_one(x):
        return x + 1.0

    add_one.__module__ = module  # as if defined in that module
    return numba.njit(cache=False)(add_one)


def test_a_compiling_kernel_of_the_package_prints_one_line_with_its_time():
    kernel, lines = _kernel("ptint_drake.systems.fake"), []
    with compile_notice(write=lines.append):
        assert kernel(1.0) == 2.0
    assert lines[0] == MESSAGE and lines[1].startswith(" done in ") and lines[1].endswith(" s\n")
    assert len(lines) == 2
    lines.clear()
    with compile_notice(write=lines.append):  # compiled now: nothing to say
        assert kernel(2.0) == 3.0
    assert lines == []


def test_another_module_or_a_disabled_notice_prints_nothing():
    lines = []
    with compile_notice(write=lines.append):
        _kernel("somebody_else")(1.0)
    with compile_notice(enabled=False, write=lines.append):
        _kernel("ptint_drake.systems.fake2")(1.0)
    assert lines == []
