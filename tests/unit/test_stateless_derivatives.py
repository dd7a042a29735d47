"""The no-op derivative override of stateless Python leaves: same derivatives, same classes,
only where the bindings need it, and systems with continuous state left alone."""

import numpy as np
from pydrake.systems.framework import DiagramBuilder, LeafSystem

from ptint_drake.worlds.stateless_derivatives import OVERRIDE_LOOKUP_THROWS, install_stateless_derivatives


class _Constant(LeafSystem):
    """No state: outputs 2."""

    def __init__(self):
        super().__init__()
        self.DeclareVectorOutputPort("y", 1, lambda context, out: out.SetAtIndex(0, 2.0))


class _Decay(LeafSystem):
    """One continuous state x, ẋ = −x + u."""

    def __init__(self):
        super().__init__()
        self.DeclareContinuousState(1)
        self._u = self.DeclareVectorInputPort("u", 1)

    def DoCalcTimeDerivatives(self, context, derivatives):
        x = context.get_continuous_state_vector().GetAtIndex(0)
        derivatives.get_mutable_vector().SetAtIndex(0, -x + self._u.Eval(context)[0])


def _diagram():
    builder = DiagramBuilder()
    source, decay = builder.AddSystem(_Constant()), builder.AddSystem(_Decay())
    builder.Connect(source.get_output_port(), decay.get_input_port())
    return builder.Build(), source, decay


def test_derivatives_and_classes_unchanged():
    diagram, source, decay = _diagram()
    context = diagram.CreateDefaultContext()
    context.SetContinuousState([0.5])
    before = diagram.EvalTimeDerivatives(context).CopyToVector()
    installed = install_stateless_derivatives(diagram)
    assert installed == (1 if OVERRIDE_LOOKUP_THROWS else 0)
    assert isinstance(source, _Constant) and type(source).__name__ == "_Constant"
    assert type(decay) is _Decay  # it has continuous state: untouched
    context.SetContinuousState([0.5])
    derivatives = diagram.AllocateTimeDerivatives()
    diagram.CalcTimeDerivatives(context, derivatives)
    np.testing.assert_array_equal(derivatives.CopyToVector(), before)
    np.testing.assert_array_equal(before, [1.5])
    assert source.get_output_port().Eval(source.GetMyContextFromRoot(context))[0] == 2.0
    assert install_stateless_derivatives(diagram) == 0  # once is enough
