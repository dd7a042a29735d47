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
        self._command = self.DeclareVectorInputPort("command", 1)
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
        goal = self.goal(float(self._command.Eval(context)[0]))
        if q[0] == goal and q[1] == goal and q[2] == 0.0 and q[3] == 0.0:
            # at rest on the goal (most steps): the update below would write the same four values
            # (step 0; no stall rule, which acts only below the goal), and Drake hands the handler
            # ``state`` already holding them — skip the finger read and the write (bit-identical)
            return
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


# Grasp states (``GraspObserver``'s output ``grasp_state``), in the spirit of the grasping states a
# Schunk WSG driver reports (IDLE / GRASPING / HOLDING / NO PART FOUND / PART LOST).
OPEN, CLOSING, HOLDING, EMPTY, LOST = 0, 1, 2, 3, 4
GRASP_STATES = ("open", "closing", "holding", "empty", "lost")


class GraspObserver(LeafSystem):
    """The grasp state decided from what a real parallel gripper reports — the finger positions
    and speeds (its encoder) and each finger drive's force (its motor current) — and the grasp
    command (the wanted opening and the expected part width), never from the plant's contact
    results, which no real driver can read.  The rule follows the grasping states of a Schunk
    WSG 50's driver (its command set: grasp a part of a given width with a force, reporting
    HOLDING, NO PART FOUND or PART LOST); the thresholds below are this package's choices.

    Every ``period`` (default 1 ms, the plant's step), with w = q_left + q_right the opening
    between the pads, ṡ = max(|v_left|, |v_right|), F = min over the two drives of the squeezing
    force (−force, N), w_part the expected width and the previous state s:

    - command > 0 (open or opening): ``open``;
    - else if s is ``holding`` or ``lost`` and w < w_hold − ``width_tolerance``: ``lost`` (the
      width collapsed: the part left the fingers), w_hold being the opening when ``holding`` was
      first decided (the encoder's reading on the part: the pads keep sinking into a part after
      that, 3.3 mm in all into a 40 mm cylinder under the 30 N hand, point contact, against about
      1 mm into a 30 mm box, so a width measured from w_part would call a held cylinder lost);
    - else if s is ``holding``: ``holding`` (it stays so while the width does not collapse);
    - else if s is ``empty``: ``empty`` (until the next open command);
    - else if w < w_part − ``width_tolerance``: ``empty`` (closed past the part's size: nothing
      between the fingers);
    - else if ṡ < ``stop_ratio`` · ``speed`` (the closing speed) and |w − w_part| ≤ ``width_tolerance`` and
      F ≥ ``force_ratio`` · ``max_force``: ``holding`` (stopped on something of the part's size,
      squeezing at the set point);
    - else ``closing`` (moving, or stopped on something not of the part's size).

    Defaults: ``width_tolerance`` 3 mm (a quarter of the pick's default 12 mm opening margin;
    the pads sink into a 30 mm part by about 1 mm under the RV-M1 hand's 30 N, point contact),
    ``stop_speed`` 10 % of the closing speed (5 mm/s for the RV-M1 hand's 50 mm/s: measured on
    conveyor_pick_place, the pads stop from 50 mm/s to 3 mm/s within 10 ms of touching the part,
    then creep at 2–4 mm/s for 0.15 s as the contact settles), ``force_ratio`` 0.9 (the drive's
    PD reaches its force limit
    within a few ms once the pads touch; ``GripperDriver``'s CLOSE_MARGIN puts the reference
    1.5 force-limit deflections behind the centre).

    =================  ====  ============================================================
    port               size  meaning
    =================  ====  ============================================================
    ``finger_state``   4     input: [q_left, q_right, v_left, v_right] (m, m/s)
    ``drive_force``    2     input: each finger drive's force (N, + opens, − squeezes)
    ``command``        1     input: the wanted opening (m); ≤ 0: close (``GripperDriver``)
    ``part_width``     1     input: the expected width of the part to grasp (m)
    ``grasp_state``    1     output: the state's code (OPEN … LOST; ``GRASP_STATES`` names)
    =================  ====  ============================================================

    Discrete state ``grasp`` = [code] and ``held_width`` = [w_hold] (m; 0 before any ``holding``),
    updated every ``period``; the output is the code (so a sample at t shows the decision of the
    update at or before t).
    """

    def __init__(self, max_force: float, speed: float, width_tolerance: float = 0.003,
                 stop_ratio: float = 0.1, force_ratio: float = 0.9, period: float = 0.001):
        super().__init__()
        self._force = force_ratio * max_force
        self._tolerance, self._stop_speed = width_tolerance, stop_ratio * speed
        self._fingers = self.DeclareVectorInputPort("finger_state", 4)
        self._drive = self.DeclareVectorInputPort("drive_force", 2)
        self._command = self.DeclareVectorInputPort("command", 1)
        self._width = self.DeclareVectorInputPort("part_width", 1)
        self._grasp = self.DeclareDiscreteState(BasicVector([float(OPEN)]))
        self._held = self.DeclareDiscreteState(BasicVector([0.0]))
        self.DeclarePeriodicDiscreteUpdateEvent(period, 0.0, self._update)
        self.DeclareStateOutputPort("grasp_state", self._grasp)

    def decide(self, previous: int, command: float, fingers, drive, part_width: float,
               held_width: float | None = None) -> int:
        """The next state from the previous one and the inputs (the rule in the class docstring);
        ``held_width``: w_hold, the opening when ``holding`` was decided (None: ``part_width``)."""
        if command > 0.0:
            return OPEN
        width = float(fingers[0]) + float(fingers[1])
        if previous in (HOLDING, LOST):
            held = part_width if held_width is None else held_width
            return LOST if width < held - self._tolerance else previous
        collapsed = width < part_width - self._tolerance
        if previous == EMPTY or collapsed:
            return EMPTY
        stopped = max(abs(float(fingers[2])), abs(float(fingers[3]))) < self._stop_speed
        squeezing = min(-float(drive[0]), -float(drive[1])) >= self._force
        if stopped and squeezing and abs(width - part_width) <= self._tolerance:
            return HOLDING
        return CLOSING

    def _update(self, context, state) -> None:
        # the command first: an open command decides ``open`` without the other inputs (most steps)
        command = float(self._command.Eval(context)[0])
        if command > 0.0:
            state.get_mutable_vector(self._grasp).SetAtIndex(0, float(OPEN))
            return
        previous = int(context.get_discrete_state(self._grasp).get_value()[0])
        held = float(context.get_discrete_state(self._held).get_value()[0])
        fingers = self._fingers.Eval(context)
        code = self.decide(previous, command, fingers, self._drive.Eval(context),
                           float(self._width.Eval(context)[0]), held)
        state.get_mutable_vector(self._grasp).SetAtIndex(0, float(code))
        if code == HOLDING and previous != HOLDING:  # the encoder's width on the part
            state.get_mutable_vector(self._held).SetAtIndex(0, float(fingers[0]) + float(fingers[1]))
