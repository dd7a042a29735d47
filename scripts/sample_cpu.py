"""Where one Monte Carlo sample's CPU time goes (issue 44: the harsh line study's budget), as JSON.

    PYTHONPATH=$PWD .venv/bin/python scripts/sample_cpu.py [SCENARIO] [--seed S] [--ranges harsh]

A study's worker runs sample after sample in one process, so one sample (seed ``S + 1000``) is run
first as a warm-up (imports, the numba kernels, the line's reach windows), then sample ``S`` plainly
— its ``cpu_s`` as ``ptint robust`` records it (``time.process_time``), and its ``simulated_s`` (a line's
run ends when the line is done, ``worlds/pick/line/truth.py``) — and once more under
cProfile, its time split by who spends it:

- ``drake_cxx``: the time inside ``AdvanceTo`` not spent in a Python system (the discrete plant
  and its contact solver, the systems framework, the C++ loggers): ``advance_over_stops``' own time;
- ``python_systems_per_step``: the Python leaf systems every step or sample calls (the
  controller, the targets, the part poses and tracker, the gripper's driver and observer, the
  contact probe): their own time;
- ``decisions``: the stops' Python (``PickRun.at_stop``: a line's looks, scheduler, IK checks);
- ``rebuilds``: the replans (``PickRun.replan``: a new diagram per decided task);
- ``setup``: drawing, parsing, the checks and the first build (``World.prepare`` and the draws);
- ``finish``: the logs, series, metrics and verdict after the run.

cProfile slows Python down, so the Python shares are overstated; ``cpu_s`` is the plain run's.

``--plant``: also the station's plant stepped alone (``plant_step_ms``: CPU ms a 1 ms step, over
``PLANT_SPAN`` s, the arm's joints locked, its inputs constant): every pool part parked and locked
(``parked``: the floor of the plant and the framework), the parts on their belts (``on_belts``) and
one of them (``one_on_belt``) — what a part resting in contact costs each step.
"""

from __future__ import annotations

import argparse
import cProfile
import json
import pstats
import time

PLANT_SPAN = 2.0  # s of the plant stepped alone (``--plant``)
PER_STEP = ("ptint_drake/controllers/", "ptint_drake/systems/", "worlds/pick/targets.py",
            "worlds/pick/part_pose.py", "worlds/pick/tracker.py", "worlds/pick/probe.py")


def _time(stats: pstats.Stats, file_end: str, function: str, own: bool = False) -> float:
    """The cumulative (or ``own``) seconds of every profiled function ``function`` of a file
    ending with ``file_end``."""
    return sum(v[2] if own else v[3] for (f, _, name), v in stats.stats.items()
               if f.endswith(file_end) and name == function)


def split(stats: pstats.Stats) -> dict:
    """Seconds per share (module docstring)."""
    per_step = sum(v[2] for (f, _, _), v in stats.stats.items() if any(p in f for p in PER_STEP))
    run = _time(stats, "worlds/runner.py", "simulate")
    return {"drake_cxx": _time(stats, "worlds/base.py", "advance_over_stops", own=True),
            "python_systems_per_step": per_step,
            "decisions": _time(stats, "worlds/pick/world.py", "at_stop"),
            "rebuilds": _time(stats, "worlds/pick/world.py", "replan"),
            "setup": _time(stats, "studies/robust.py", "robust_sample") - run
            + _time(stats, "worlds/pick/world.py", "prepare"),
            "finish": _time(stats, "worlds/pick/world.py", "finish")}


def plant_step_ms(scenario, on_belt: int) -> float:
    """CPU ms a step of ``scenario``'s station alone (``--plant``), the first ``on_belt`` pool parts
    on their belts (their default poses) and the others parked and locked (``line.truth``)."""
    import numpy as np  # noqa: PLC0415
    from pydrake.systems.framework import DiagramBuilder  # noqa: PLC0415
    from pydrake.systems.primitives import ConstantVectorSource  # noqa: PLC0415

    from ptint_drake.worlds.base import new_simulator  # noqa: PLC0415
    from ptint_drake.worlds.pick.cell import world_config  # noqa: PLC0415
    from ptint_drake.worlds.pick.line.truth import parking_pose  # noqa: PLC0415
    from ptint_drake.worlds.pick.station import MakePickStation  # noqa: PLC0415

    station = MakePickStation(world_config(scenario))
    builder = DiagramBuilder()
    st = builder.AddSystem(station.diagram)
    plant = station.plant
    for port, value in (("actuation", np.zeros(plant.num_actuated_dofs(station.arm))),
                        ("gripper_command", [scenario.pick.gripper.initial_opening])):
        source = builder.AddSystem(ConstantVectorSource(value))
        builder.Connect(source.get_output_port(), st.GetInputPort(port))
    simulator = new_simulator(builder.Build())
    pc = plant.GetMyMutableContextFromRoot(simulator.get_mutable_context())
    station.start_running(pc)
    for index in plant.GetJointIndices(station.arm):
        if plant.get_joint(index).num_velocities():
            plant.get_joint(index).Lock(pc)
    for k, body in enumerate(station.parts[on_belt:], start=on_belt):
        plant.SetFreeBodyPose(pc, body, parking_pose(k))
        plant.SetVelocities(pc, body.model_instance(), np.zeros(6))
        (index,) = plant.GetJointIndices(body.model_instance())
        plant.get_joint(index).Lock(pc)
    simulator.Initialize()
    t0 = time.process_time()
    simulator.AdvanceTo(PLANT_SPAN)
    return 1e3 * (time.process_time() - t0) / round(PLANT_SPAN / plant.time_step())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenario", nargs="?", default="line_assembly")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--ranges", default="harsh")
    parser.add_argument("--plant", action="store_true", help="also the plant stepped alone (docstring)")
    args = parser.parse_args()
    from ptint_drake.simulation.scenario import scenario_text  # noqa: PLC0415
    from ptint_drake.studies.robust import PRESETS, robust_sample  # noqa: PLC0415

    name, text = scenario_text(args.scenario)
    ranges = PRESETS[args.ranges]
    robust_sample(text, name, args.seed + 1000, ranges)  # the warm-up a worker's first sample pays
    row = robust_sample(text, name, args.seed, ranges)
    profiler = cProfile.Profile(time.process_time)  # CPU seconds: the wall time depends on the load
    t0 = time.process_time()
    profiler.enable()
    robust_sample(text, name, args.seed, ranges)
    profiler.disable()
    profiled = time.process_time() - t0
    report = {"scenario": name, "seed": args.seed, "ranges": args.ranges, "status": row["status"],
              "cpu_s": row["cpu_s"], "simulated_s": row.get("simulated_s"), "profiled_cpu_s": profiled,
              "profiled_split_s": split(pstats.Stats(profiler))}
    if args.plant:
        from ptint_drake.studies.robust import sample_scenario  # noqa: PLC0415
        from ptint_drake.worlds.registry import world_of  # noqa: PLC0415

        drawn = sample_scenario(text, name, args.seed, ranges)[0]
        scenario = world_of(drawn).prepare(drawn).scenario  # (a line's: its pool of parts)
        n = len(scenario.pick.parts)
        report["plant_step_ms"] = {"parked": plant_step_ms(scenario, 0),
                                   "one_on_belt": plant_step_ms(scenario, 1),
                                   "on_belts": plant_step_ms(scenario, n), "parts": n}
    print(json.dumps(report, indent=2))


if __name__ == "__main__":
    main()
