"""A Python leaf system without continuous state answers the simulator's derivative call
cheaply on every Drake version.

``Diagram::DoCalcTimeDerivatives`` asks *every* subsystem for its derivatives at every
evaluation, those with no continuous state included.  For a ``LeafSystem`` subclass written
in Python the call goes through the binding's trampoline, which looks for a Python method
``DoCalcTimeDerivatives``.  Drake's nanobind bindings (Drake ≥ 1.55 or so) do not bind that
method on ``LeafSystem``, so the look-up fails and the binding throws and catches a C++
exception each time before falling back to the C++ default: ≈ 10 µs per Python leaf per
evaluation on Drake 1.58 (measured: 5 Python leaves, 53 µs per ``CalcTimeDerivatives``;
with the no-op below, 5 µs).  With the pybind11 bindings (Drake 1.51) the method exists,
the look-up succeeds, and nothing is installed (a Python call would cost more there than
the C++ default).

``install_stateless_derivatives(diagram)`` moves each such leaf (Python class, no
continuous state, no ``DoCalcTimeDerivatives`` of its own) to a subclass of its class that
adds a ``DoCalcTimeDerivatives`` doing nothing — exactly what the C++ default does for a
system with no continuous state (its derivative vector is empty).  The binding looks the
method up on the class, not on the instance, hence the subclass (one per class, same name
and module; ``isinstance`` is unchanged).  Results do not change.
"""

from __future__ import annotations

import functools

from pydrake.systems.framework import Diagram, LeafSystem

#: True where the bindings lack ``LeafSystem.DoCalcTimeDerivatives`` (nanobind): only there
#: does a Python leaf's derivative call pay for a failed override look-up.
OVERRIDE_LOOKUP_THROWS = not hasattr(LeafSystem, "DoCalcTimeDerivatives")


def _no_derivatives(self, context, derivatives) -> None:
    """The derivatives of a system with no continuous state: none (an empty vector)."""


@functools.cache
def _stateless_class(cls: type) -> type:
    """``cls`` with the no-op ``DoCalcTimeDerivatives`` (same name, module and docstring)."""
    return type(cls.__name__, (cls,), {"DoCalcTimeDerivatives": _no_derivatives,
                                       "__module__": cls.__module__, "__qualname__": cls.__qualname__,
                                       "__doc__": cls.__doc__})


def _python_leaves(diagram: Diagram):
    """Every leaf of ``diagram`` (nested diagrams walked) whose class is written in Python."""
    for system in diagram.GetSystems():
        if isinstance(system, Diagram):
            yield from _python_leaves(system)
        elif isinstance(system, LeafSystem) and type(system).__module__.split(".")[0] != "pydrake":
            yield system


def install_stateless_derivatives(diagram: Diagram) -> int:
    """Give every Python leaf of ``diagram`` without continuous state a no-op
    ``DoCalcTimeDerivatives`` where the bindings need one (see the module docstring);
    returns how many leaves got it (0 on bindings that do not need it)."""
    if not OVERRIDE_LOOKUP_THROWS:
        return 0
    count = 0
    for system in _python_leaves(diagram):
        if system.num_continuous_states() == 0 and not hasattr(system, "DoCalcTimeDerivatives"):
            system.__class__ = _stateless_class(type(system))
            count += 1
    return count
