"""``GripperDriver`` — the parallel gripper's drive: an opening command in, finger references out.

A motor-operated hand closes its jaws at a limited speed and squeezes with a limited force.  This
driver is the speed part: every ``period`` it moves each finger's reference position q_d (the
distance of the pad from the centre plane, m) toward the commanded one by at most
``speed · period`` and outputs the reference state [q_d; v_d] (v_d = the reference's speed).  The
force part is in the plant: the finger joints are Drake PD-controlled actuators (stiffness kp,
damping kd, effort limit = the grip force limit ``max_force``, ``pick.scene.AddGripper``), so the
force on each finger is clamp(kp (q_d − q) + kd (v_d − v), ±max_force), computed implicitly by
the discrete contact solver.  So it uses the gripper's model: its PD gains and force limit (to
place the closing reference where the clamp is reached).

Command (input ``command``, 1 value, m): the wanted opening between the pads.
- ``command > 0``: go to that opening (``stroke``, the gripper's largest, = fully open);
- ``command ≤ 0``: **close** — the reference runs (at ``speed``) to CLOSE_MARGIN · max_force / kp
  behind the centre plane, so once the pads touch a part the squeeze rises within a few ms to
  ``max_force`` per finger and stays there.
A task sequencer closes the fingers at a prescribed time by switching ``command`` to 0 then.

=================  ====  =================================================================
port               size  meaning
=================  ====  =================================================================
``command``        1     input: wanted opening (m); ≤ 0: close with the force limit
``finger_state``   4     input: the fingers' [q_left, q_right, v_left, v_right] (m, m/s): when
                         opening, a reference behind a finger (stalled on a part) starts from it
``desired_state``  4     output: [q_d_left, q_d_right, v_d_left, v_d_right] (m, m/s): the
                         gripper model instance's desired-state input
=================  ====  =================================================================

Discrete state ``reference`` = [q_d_left, q_d_right, v_d_left, v_d_right], updated every
``period`` (default 1 ms: the plant's step).
"""

from __future__ import annotations

from pydrake.systems.framework import BasicVector, LeafSystem

CLOSE_MARGIN = 1.5  # the closing reference lies this many force-limit deflections behind the centre


class GripperDriver(LeafSystem):
    """Rate-limited finger references for a PD-actuated parallel gripper (module docstring)."""

    def __init__(self, stroke: float, speed: float, max_force: float, kp: float,
                 initial_opening: float, period: float = 0.001):
        super().__init__()
        self._half_stroke, self._step, self._period = stroke / 2, speed * period, period
        self._closed = -CLOSE_MARGIN * max_force / kp
        q0 = initial_opening / 2
        self.DeclareVectorInputPort("command", 1)
        self._fingers = self.DeclareVectorInputPort("finger_state", 4)
        self._reference = self.DeclareDiscreteState(BasicVector([q0, q0, 0.0, 0.0]))
        self.DeclarePeriodicDiscreteUpdateEvent(period, 0.0, self._update)
        self.DeclareStateOutputPort("desired_state", self._reference)

    def goal(self, command: float) -> float:
        """Each finger's reference goal (m from the centre plane) for an opening command."""
        if command <= 0.0:
            return self._closed
        return min(command, 2 * self._half_stroke) / 2

    def _update(self, context, state):
        # plain floats: this runs every millisecond (numpy's small-array calls cost ~10× more)
        q = context.get_discrete_state(self._reference).get_value()
        goal = self.goal(float(self.get_input_port(0).Eval(context)[0]))
        fingers = self._fingers.Eval(context)
        out = [0.0, 0.0, 0.0, 0.0]
        for i in (0, 1):
            qi = float(q[i])
            # a drive that stalled on a part opens from where its fingers are, not from its
            # reference deep behind them (which would keep squeezing while it travels back)
            if goal > qi:
                qi = max(qi, float(fingers[i]))
            step = min(max(goal - qi, -self._step), self._step)
            out[i], out[2 + i] = qi + step, step / self._period
        state.get_mutable_vector(self._reference).SetFromVector(out)
