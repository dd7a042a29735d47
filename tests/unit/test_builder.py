"""AddPrescribedTimeInterceptor composed by hand into diagrams of robots that are not the RV-M1."""

import numpy as np
import pytest
from arms import OFFSET_ARM, REDUNDANT_ARM
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import LogVectorOutput

from ptint_drake.controllers.ptsmc.builder import AddPrescribedTimeInterceptor, ControllerGains
from ptint_drake.systems.task.schedule import Schedule, Segment
from ptint_drake.systems.task.targets import LinearTarget, WaypointTarget


@pytest.mark.parametrize("urdf, q0", [(OFFSET_ARM, [0.3, 0.5, 1.2]),
                                      (REDUNDANT_ARM, [0.3, 0.5, 1.0, 0.4])])
def test_interceptor_composes_with_another_robot(urdf, q0):
    builder = DiagramBuilder()
    # a user's own diagram: plant with SceneGraph, the interceptor added on top
    plant, _ = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
    Parser(plant).AddModelsFromString(urdf, "urdf")
    plant.Finalize()
    hand = plant.GetFrameByName("hand")
    ctx0 = plant.CreateDefaultContext()
    plant.SetPositions(ctx0, q0)
    x0 = hand.CalcPoseInWorld(ctx0).translation()
    target = LinearTarget(x0 + [0.06, -0.08, -0.05], [0.0, 0.1, 0.0])
    tf = 1.0
    schedule = Schedule([Segment(0.0, tf, 0.75)])
    h = AddPrescribedTimeInterceptor(builder, plant, hand, schedule, [target], ControllerGains())
    log = LogVectorOutput(h.surface.GetOutputPort("e"), builder, publish_period=0.0)
    diagram = builder.Build()
    sim = Simulator(diagram)
    sim.get_mutable_integrator().set_target_accuracy(1e-4)
    context = sim.get_mutable_context()
    plant.SetPositions(plant.GetMyMutableContextFromRoot(context), q0)
    e_port = h.surface.GetOutputPort("e")
    sc = h.surface.GetMyContextFromRoot(context)
    e0 = np.linalg.norm(e_port.Eval(sc))
    sim.AdvanceTo(0.5 * tf)
    e_half = np.linalg.norm(e_port.Eval(sc))
    sim.AdvanceTo(tf)
    e_tf = np.linalg.norm(e_port.Eval(sc))
    sim.AdvanceTo(1.5 * tf)
    data = log.FindLog(context)
    e_after = np.linalg.norm(data.data()[:, data.sample_times() >= tf], axis=0)
    assert e0 > 0.1
    assert e_tf < 1e-3, f"|e(tf)| = {e_tf}"
    assert e_half >= 0.25 * e0, f"arrived early: {e_half} vs e0 {e0}"
    assert np.max(e_after) < 3e-3


def test_rejects_plants_it_cannot_drive():
    from pydrake.multibody.plant import MultibodyPlant

    builder = DiagramBuilder()
    plant = builder.AddSystem(MultibodyPlant(0.0))
    Parser(plant).AddModelsFromString(OFFSET_ARM, "urdf")
    with pytest.raises(ValueError, match="finalized"):
        AddPrescribedTimeInterceptor(builder, plant, plant.world_frame(),
                                     Schedule([Segment(0, 1, 0.5)]), [LinearTarget([0, 0, 0], [0, 0, 0])])


def _closed_loop(urdf, fused, gains, schedule, target):
    builder = DiagramBuilder()
    plant, _ = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
    Parser(plant).AddModelsFromString(urdf, "urdf")
    plant.Finalize()
    h = AddPrescribedTimeInterceptor(builder, plant, plant.GetFrameByName("hand"), schedule, [target],
                                     gains, fused=fused)
    return builder.Build(), plant, h


@pytest.mark.parametrize("urdf, q, gains", [
    (OFFSET_ARM, [0.3, 0.5, 1.2], ControllerGains()),
    (OFFSET_ARM, [0.3, 0.5, 1.2], ControllerGains(pinv_damping=0.05, switching="sat")),
    (REDUNDANT_ARM, [0.3, 0.5, 1.0, 0.4], ControllerGains(null_space_damping=2.0))])
def test_fused_and_blocks_compute_the_same_floats(urdf, q, gains):
    """The fused system and the five blocks call the same functions: the same torque to the last
    bit, mid-segment and in the hold, for a given state, σ and captured s(t0)."""
    schedule = Schedule([Segment(0.0, 1.0, 0.75)])
    target = LinearTarget([0.35, -0.1, 0.5], [0.0, 0.1, 0.0])
    rng = np.random.default_rng(len(q))
    v = rng.normal(scale=0.3, size=len(q))
    sigma, s0 = rng.normal(scale=0.01, size=(2, 3))
    torques = []
    for fused in (True, False):
        diagram, plant, h = _closed_loop(urdf, fused, gains, schedule, target)
        ctx = diagram.CreateDefaultContext()
        diagram.ExecuteInitializationEvents(ctx)
        plant.SetPositionsAndVelocities(plant.GetMyMutableContextFromRoot(ctx), np.r_[q, v])
        system = h.fused if fused else h.surface
        sub = system.GetMyMutableContextFromRoot(ctx)
        sub.SetContinuousState(sigma)
        # [index, s(t0)], and the fused law's σ0 (0: σ kept across segments)
        sub.SetDiscreteState(np.r_[0.0, s0, np.zeros(len(s0))] if fused else np.r_[0.0, s0])
        row = []
        for t in (0.4, 1.3):
            ctx.SetTime(t)
            out = h.fused.GetOutputPort("tau") if fused else h.controller.GetOutputPort("tau")
            row.append(out.Eval(out.get_system().GetMyContextFromRoot(ctx)).tolist())
        torques.append(row)
    assert torques[0] == torques[1]
    assert all(np.all(np.isfinite(r)) and np.any(np.abs(r) > 1e-3) for r in torques[0])


@pytest.mark.parametrize("own_targets", [True, False])
def test_fused_law_reads_one_loop_input(own_targets):
    """The law has one input, ``loop`` = [q; v; σ; captured (fed back); target (without target
    objects)]; its [τ; σ̇] (the compiled output path) equals the ``row`` the telemetry uses, on
    the same values to the last bit, with σ reset (σ − σ0) at a segment start."""
    schedule = Schedule([Segment(0.0, 1.0, 0.75)])
    target = LinearTarget([0.35, -0.1, 0.5], [0.0, 0.1, 0.0])
    builder = DiagramBuilder()
    plant, _ = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
    Parser(plant).AddModelsFromString(OFFSET_ARM, "urdf")
    plant.Finalize()
    h = AddPrescribedTimeInterceptor(builder, plant, plant.GetFrameByName("hand"), schedule,
                                     [target] if own_targets else None, ControllerGains(sigma_policy="reset"),
                                     fused=True)
    if not own_targets:
        builder.ExportInput(h.target_input, "target")
    diagram = builder.Build()
    law = h.fused.law
    assert [law.get_input_port(i).get_name() for i in range(law.num_input_ports())] == ["loop"]
    assert law.get_input_port(0).size() == 6 + 3 + 7 + (0 if own_targets else 9)
    ctx = diagram.CreateDefaultContext()
    if not own_targets:
        diagram.get_input_port(0).FixValue(ctx, target.evaluate(0.4)[:9])
    diagram.ExecuteInitializationEvents(ctx)
    rng = np.random.default_rng(7)
    plant.SetPositionsAndVelocities(plant.GetMyMutableContextFromRoot(ctx),
                                    np.r_[0.3, 0.5, 1.2, rng.normal(scale=0.3, size=3)])
    sub = h.fused.GetMyMutableContextFromRoot(ctx)
    sub.SetContinuousState(rng.normal(scale=0.01, size=3))
    captured = np.r_[0.0, rng.normal(scale=0.01, size=6)]
    sub.SetDiscreteState(captured)
    ctx.SetTime(0.4)
    lctx = law.GetMyContextFromRoot(ctx)
    qv, sigma, seen, tg = law.loop_values(lctx)
    assert seen.tolist() == captured.tolist() and (tg is None) == own_targets
    out = law.GetOutputPort("tau_sigma_dot").Eval(lctx)
    row = law.row(0.4, qv, sigma, seen, tg)
    tau, sigma_dot = row[law.layout["tau"]], row[law.telemetry_size + 5:]
    assert out.tolist() == np.r_[tau, sigma_dot].tolist()
    assert row[law.layout["sigma"]].tolist() == (sigma - captured[4:]).tolist()
    assert np.any(np.abs(tau) > 1e-3)


def test_fused_waypoint_target_equals_blocks():
    """A target without a compiled row (waypoints) is evaluated in Python on the fused path too:
    the same torque as the blocks (the compiled output once read a zero target row here)."""
    target = WaypointTarget([0.0, 0.5, 1.0, 1.5], [[0.35, -0.1, 0.5], [0.35, -0.05, 0.5],
                                                   [0.35, 0.0, 0.52], [0.35, 0.05, 0.5]])
    torques = []
    for fused in (True, False):
        diagram, plant, h = _closed_loop(OFFSET_ARM, fused, ControllerGains(),
                                         Schedule([Segment(0.0, 1.0, 0.75)]), target)
        ctx = diagram.CreateDefaultContext()
        diagram.ExecuteInitializationEvents(ctx)
        plant.SetPositions(plant.GetMyMutableContextFromRoot(ctx), [0.3, 0.5, 1.2])
        ctx.SetTime(0.4)
        out = (h.fused if fused else h.controller).GetOutputPort("tau")
        torques.append(out.Eval(out.get_system().GetMyContextFromRoot(ctx)).tolist())
    assert torques[0] == torques[1]
