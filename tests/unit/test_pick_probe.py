"""``PickProbe``: a recorder read after the run — its samples line up with the run's loggers, its
poses are the plant's, its collision flags are the station's live ``CollisionProbe``'s."""

import numpy as np
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import LogVectorOutput

from ptint_drake.simulation.scenario import load_scenario
from ptint_drake.worlds.pick.probe import PART_WIDTH
from ptint_drake.worlds.pick.cell import PROBE_PERIOD, world_config
from ptint_drake.worlds.pick.run import AddPickProbe
from ptint_drake.worlds.pick.station import MakePickStation

INTO_BELT_DEG = [0.0, 76.2, -5.9, 17.7, 0.0]  # the fingers inside the belt (test_pick_collisions)


def _recorded(initial_q_deg, until: float = 0.02, max_copies: int | None = None):
    config = world_config(load_scenario("conveyor_pick_place"))
    config.initial_q_deg = initial_q_deg
    station = MakePickStation(config)
    builder = DiagramBuilder()
    st = builder.AddNamedSystem("pick_station", station.diagram)
    probe = AddPickProbe(builder, st, station)
    if max_copies is not None:
        probe.max_copies = max_copies
    states = LogVectorOutput(st.GetOutputPort("plant_state"), builder, PROBE_PERIOD)
    collisions = LogVectorOutput(st.GetOutputPort("collisions"), builder, PROBE_PERIOD)
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    st.GetInputPort("actuation").FixValue(st.GetMyMutableContextFromRoot(context), np.zeros(5))
    st.GetInputPort("gripper_command").FixValue(st.GetMyMutableContextFromRoot(context),
                                                [config.gripper.initial_opening])
    simulator = Simulator(diagram, context)
    simulator.AdvanceTo(until / 2)
    simulator.AdvanceTo(until)
    diagram.ForcedPublish(context)  # a forced publish is a sample too (VectorLogSink's triggers)
    probe_context = probe.GetMyContextFromRoot(context)
    t, rows = probe.log(probe_context)
    probe.read = probe.copies_read(probe_context)
    return station, probe, t, rows, states.FindLog(context), collisions.FindLog(context)


def test_samples_line_up_with_the_loggers_and_poses_are_the_plants():
    station, probe, t, rows, states, _ = _recorded([0.0, 30.0, 30.0, -60.0, 0.0])
    assert np.array_equal(t, states.sample_times()) and len(t) == 12, (t, states.sample_times())
    plant = station.plant
    for k, part in enumerate(station.parts):  # a free body: its q is [w x y z, x y z]
        q = states.data().T[:, :plant.num_positions()]
        i = part.floating_positions_start()
        assert np.allclose(rows[:, PART_WIDTH * k: PART_WIDTH * k + 3], q[:, i + 4:i + 7], atol=1e-12)
        quaternion = q[:, i:i + 4] / np.linalg.norm(q[:, i:i + 4], axis=1, keepdims=True)
        sign = np.sign(np.sum(quaternion * rows[:, PART_WIDTH * k + 3: PART_WIDTH * k + 7], axis=1))
        assert np.allclose(rows[:, PART_WIDTH * k + 3: PART_WIDTH * k + 7], sign[:, None] * quaternion,
                           atol=1e-9)
    assert not np.any(rows[:, probe.blocks["collisions"]])  # a start pose clear of everything


def test_collision_flags_are_the_stations_and_a_fresh_context_has_no_samples():
    station, probe, t, rows, _, collisions = _recorded(INTO_BELT_DEG)
    flags = rows[:, probe.blocks["collisions"]]
    assert np.array_equal(flags, collisions.data().T), (flags, collisions.data().T)
    belt = station.obstacles.index("belt")
    assert np.all(flags[1:, 2 * belt:2 * belt + 2].any(axis=1))  # the fingers in the belt, every step on
    assert rows[1:, probe.blocks["probe"].stop - 8].all()  # and the belt flag
    fresh = probe.CreateDefaultContext()
    assert len(probe.log(fresh)[0]) == 0


def test_copies_read_during_the_run_past_the_bound_give_the_same_rows():
    _, probe, t, rows, _, _ = _recorded(INTO_BELT_DEG)
    _, bounded, t_bounded, rows_bounded, _, _ = _recorded(INTO_BELT_DEG, max_copies=3)
    assert bounded.read == 9 and probe.read == 0  # 12 samples, 3 copies kept at most
    assert np.array_equal(t, t_bounded) and np.array_equal(rows, rows_bounded)
    assert rows[:, probe.blocks["collisions"]].any()  # (there were robot contacts to read)
