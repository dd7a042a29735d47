"""Issue 43, "no message carries truth": a pick without a camera aims by its station's part
tracker (``worlds.pick.tracker``), a sensor port, in ``ptint run`` and across ``ptint hardware``'s
link alike.  The station's truth ports (``part_k_pose``, ``part_k_rotation``: the parts' simulated
motion) feed no system of the one-process diagram; the drive's inputs are the arm's status, the
gripper's status and the tracker's reports; and a pair run over an in-memory LCM (every message
both sides publish seen by a bystander subscribed to all channels) puts on the wire only the
devices' channels, none named for part motion or truth, the tracker's with no accelerations."""

from __future__ import annotations

import re

import numpy as np
from pydrake.lcm import DrakeLcm

from ptint_drake.hardware.drive import DriveDiagram
from ptint_drake.hardware.in_memory import run_pair
from ptint_drake.hardware.link import unpack_tracked
from ptint_drake.hardware.session import LinkSettings
from ptint_drake.simulation.scenario import load_scenario
from ptint_drake.worlds.base import TRACKED_SIZE
from ptint_drake.worlds.pick.run import build_pick

PICK = "conveyor_pick_place"
TRUTH_WORDS = r"PART|MOTION|TRUTH|TRUE|GROUND"
DEVICES = {"IIWA_STATUS", "IIWA_COMMAND", "SCHUNK_WSG_STATUS", "SCHUNK_WSG_COMMAND", "TRACKED_POSES"}


def _readers(diagram, system, port_names) -> list:
    """The (system, input) pairs of ``diagram`` fed by ``system``'s outputs named ``port_names``."""
    out = []
    for (reader, i), (source, j) in diagram.connection_map().items():
        if source is system and source.get_output_port(j).get_name() in port_names:
            out.append((reader.get_name(), reader.get_input_port(i).get_name()))
    return out


def test_no_truth_port_feeds_the_one_process_run():
    built = build_pick(load_scenario(PICK))
    station = built.diagram.GetSubsystemByName("pick_station")
    count = len(built.station.parts)
    truth = {f"part_{k}_{what}" for k in range(count) for what in ("pose", "rotation")}
    assert _readers(built.diagram, station, truth) == []
    # the targets read the tracker (the check can fail: this is the very connection it looks for)
    assert _readers(built.diagram, station, {"tracked_poses"}) == [("tracked_parts", "tracked_poses")]


def test_the_drive_takes_the_devices_reports_only():
    diagram = DriveDiagram(load_scenario(PICK))[0]
    inputs = {diagram.get_input_port(i).get_name(): diagram.get_input_port(i).size()
              for i in range(diagram.num_input_ports())}
    assert inputs.pop("state") > 0  # the arm's [q; v]
    assert inputs == {"tracked_poses": TRACKED_SIZE, "gripper": 6}


def test_the_wire_carries_the_devices_channels_only(tmp_path):
    scenario = load_scenario(PICK)
    lcm = DrakeLcm("memq://")
    seen: dict[str, list] = {}
    lcm.SubscribeAllChannels(lambda channel, data: seen.setdefault(channel, []).append(bytes(data)))
    # (and in lockstep a lost gripper status is re-sent with its status: no tick lost)
    settings = LinkSettings(period=1e-3, duration=scenario.duration, drop_companion=1.0)
    metrics, drive = run_pair(scenario, settings, tmp_path, lcm=lcm)
    assert metrics["hardware"]["fault"] is None and metrics["status"] == "ok"
    assert metrics["hardware"]["companions_dropped"] == 1 and drive["companions_lost"] == 0
    assert set(seen) == DEVICES and not any(re.search(TRUTH_WORDS, c) for c in seen), sorted(seen)
    assert drive["subscribed_channels"] == ["IIWA_STATUS", "SCHUNK_WSG_STATUS", "TRACKED_POSES"]
    utime, report = unpack_tracked(seen["TRACKED_POSES"][-1], 1)  # [p, v, R, ω]: no acceleration
    assert report.size == TRACKED_SIZE and np.all(np.isfinite(report))
    assert abs(np.linalg.det(report[6:15].reshape(3, 3)) - 1.0) < 1e-9
