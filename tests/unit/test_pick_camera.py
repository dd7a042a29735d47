"""The pick world with an RGB-D camera (issue 34): random placement, the wiring (the targets read
the estimates, the perception only the depth image), symmetry, and the rejections before a run."""

import numpy as np
import pytest
from pydrake.math import RotationMatrix

from ptint_drake import cli
from ptint_drake.config.pick import PartConfig
from ptint_drake.simulation.scenario import load_scenario
from ptint_drake.worlds.pick.metrics import _place_angle
from ptint_drake.worlds.pick.placement import nominal_parts, placed_parts
from ptint_drake.worlds.pick.run import build_pick
from ptint_drake.worlds.pick.tasks import Replan, pick_plan


def test_random_placement_is_drawn_from_the_seed_within_its_ranges():
    parts = [PartConfig(yaw_deg="random", lateral=[-0.015, 0.015], offset=-0.15, offset_jitter=0.02)]
    draws = [placed_parts(parts, seed)[0] for seed in range(20)]
    assert all(-0.015 <= p.lateral <= 0.015 and abs(p.offset + 0.15) <= 0.02 for p in draws)
    assert all(-180.0 <= p.yaw_deg < 180.0 for p in draws)
    assert len({round(p.yaw_deg, 6) for p in draws}) == 20  # a new yaw per seed
    assert placed_parts(parts, 3)[0] == placed_parts(parts, 3)[0]
    nominal = nominal_parts(parts)[0]
    assert (nominal.yaw_deg, nominal.lateral, nominal.offset) == (0.0, 0.0, -0.15)
    fixed = [PartConfig(yaw_deg=30.0, lateral=0.01)]
    assert placed_parts(fixed, 1) is fixed  # nothing random: the same parts


def test_the_targets_read_the_estimates_and_the_perception_only_the_image():
    built = build_pick(load_scenario("conveyor_pick_place_rgbd"))
    links = built.diagram.connection_map()
    station = built.diagram.GetSubsystemByName("pick_station")
    sources = {(s.get_name(), s.get_output_port(p).get_name()) for (d, i), (s, p) in links.items()
               if d is built.targets}
    assert sources == {("estimated_parts", "part_0_pose"), ("estimated_parts", "part_0_rotation")}
    perception = built.diagram.GetSubsystemByName("rgbd_perception")
    feeds = [(s, s.get_output_port(p).get_name()) for (d, i), (s, p) in links.items() if d is perception]
    assert feeds == [(station, "depth_image")] and perception.num_input_ports() == 1


def test_the_place_angle_folds_by_the_parts_symmetry():
    R = RotationMatrix.MakeZRotation(np.radians(90.0)).matrix()
    assert _place_angle(R, 0.0, "box", [0.03, 0.03, 0.03]) == pytest.approx(0.0, abs=1e-9)
    assert _place_angle(R, 0.0, "box", [0.03, 0.02, 0.03]) == pytest.approx(90.0)
    assert _place_angle(RotationMatrix.MakeZRotation(2.0).matrix(), 0.0, "cylinder", [0.03, 0.03]) == \
        pytest.approx(0.0, abs=1e-6)


def test_an_unseen_part_gets_no_descend_and_no_close_command():
    pick = load_scenario("conveyor_pick_place_rgbd").pick
    plan = pick_plan(pick)
    descend = plan.schedule.segments[plan.segment_index(0, "descend")].start
    aborted = pick_plan(pick, (Replan((), 0.0, abort=descend),))
    assert [s.phase for s in aborted.segments][:2] == ["approach", "backoff"]
    assert all(opening > 0.0 for _, opening in aborted.commands)  # the fingers never close
    assert any(opening == 0.0 for _, opening in plan.commands)


@pytest.mark.parametrize("setting, field", [
    ("measurement=null", "pick.parts[0].yaw_deg"),  # random placement needs the camera
    ("measurement.camera.look_at=[0.9, 0.9, 0.65]", "measurement.camera"),  # pointed away
    ("measurement.sensor=pose", "measurement.camera"),
    ("pick.parts[0].yaw_deg=sideways", "pick.parts[0].yaw_deg"),
    ("pick.parts[0].lateral=[0.01, -0.01]", "pick.parts[0].lateral"),
    ("pick.parts[0].offset_jitter=-0.01", "pick.parts[0].offset_jitter"),
])
def test_no_camera_or_one_pointed_away_is_rejected_before_the_run(setting, field, capsys, tmp_path):
    code = cli.main(["run", "conveyor_pick_place_rgbd", "--set", setting, "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err.strip()
    assert code == 2
    assert len(err.splitlines()) == 1 and f"{field}" in err, err
    assert not (tmp_path / "o").exists()


def test_parts_of_different_shapes_and_sizes_are_classified_with_a_camera():
    # issue 44: no longer refused; the perception fits each cluster against the declared kinds
    from pathlib import Path  # noqa: PLC0415

    from ptint_drake.simulation.scenario import parse_with_overrides  # noqa: PLC0415
    from ptint_drake.worlds.pick.part_tracks import catalog  # noqa: PLC0415

    root = Path(__file__).resolve().parents[2]
    text = (root / "ptint_drake/scenarios/assembly_pick_place_rgbd.yaml").read_text()
    scenario = parse_with_overrides(text, ["pick.parts[1].size=[0.03, 0.02, 0.03]",
                                           "pick.parts[2].shape=cylinder", "pick.parts[2].size=[0.04, 0.03]"])
    kinds, of = catalog(scenario.pick)
    assert kinds == [("box", [0.03, 0.03, 0.03]), ("box", [0.03, 0.02, 0.03]), ("cylinder", [0.04, 0.03])]
    assert of == [0, 1, 2]
    built = build_pick(scenario)
    config = built.estimates.estimator._c
    assert config.kinds() == kinds and config.tracking.objects == [(0, 0), (1, 1), (2, 2)]
    assert config.tracking.arrival == [0, 1, 2]  # downstream first (offsets -0.12, -0.45, -0.78)


def test_a_robust_sample_of_an_rgbd_pick_draws_a_new_placement():
    from ptint_drake.studies import robust  # noqa: PLC0415
    from ptint_drake.worlds.pick import studies  # noqa: PLC0415

    def draw(seed):  # the same draws of the sample's own generator: only the placement's seed differs
        scenario, _ = studies.robust_sample(load_scenario("conveyor_pick_place_rgbd"), "c", seed,
                                            robust.Draws(np.random.default_rng(0), robust.MILD))
        return placed_parts(scenario.pick.parts, scenario.measurement.seed)[0]

    a, b = draw(3), draw(4)
    assert a.yaw_deg != b.yaw_deg and a.lateral != b.lateral


@pytest.mark.parametrize("preset, xyz, rpy", [("mild", 0.0005, 0.1), ("harsh", 0.0005, 0.1),
                                              ("calibration", 0.002, 0.5)])
def test_robust_draws_an_rgbd_picks_camera_errors_and_placement_from_its_preset(preset, xyz, rpy):
    """The camera's calibration error and depth-noise scale come from the ``--ranges`` preset;
    every part is placed at any yaw and within ±15 mm across its belt (issue 34), whatever the
    scenario's own range."""
    from ptint_drake.simulation.scenario import scenario_text
    from ptint_drake.studies import robust
    from ptint_drake.worlds.pick.placement import placed_parts

    name, text = scenario_text("assembly_pick_place_rgbd")
    ranges = robust.PRESETS[preset]
    pose, yaws, laterals, scales = [], [], [], []
    for seed in range(12):
        scenario, params = robust.sample_scenario(text, name, seed, ranges)
        assert all(p.yaw_deg == "random" and p.lateral == [-0.015, 0.015] for p in scenario.pick.parts)
        placed = placed_parts(scenario.pick.parts, scenario.measurement.seed)
        assert [p.lateral for p in placed] == params["placed_lateral"]
        pose.append(params["camera_pose_error"])
        scales.append(params["depth_noise_scale"])
        yaws += params["placed_yaw_deg"]
        laterals += params["placed_lateral"]
    pose = np.abs(np.array(pose))
    assert pose[:, 0:3].max() <= xyz and pose[:, 0:3].max() > 0.6 * xyz
    assert pose[:, 3:6].max() <= rpy and pose[:, 3:6].max() > 0.6 * rpy
    assert 0.5 <= min(scales) and max(scales) <= 2.0
    assert max(np.abs(laterals)) <= 0.015 and max(np.abs(laterals)) > 0.01
    assert min(yaws) < -90.0 and max(yaws) > 90.0


def test_a_narrow_belt_clips_the_robust_lateral_range_to_its_half_width():
    from ptint_drake.simulation.scenario import scenario_text
    from ptint_drake.studies import robust

    name, text = scenario_text("conveyor_pick_place_rgbd")
    ranges = robust.MILD | {"placed_lateral": (-0.5, 0.5)}
    scenario, _ = robust.sample_scenario(text, name, 3, ranges)
    half = scenario.pick.belts[0].width / 2
    assert scenario.pick.parts[0].lateral == [-half, half]


def test_a_part_that_can_reach_onto_the_next_belt_is_warned_about_before_the_run():
    """40 mm belts 50 mm apart (assembly_pick_place's) with parts ±15 mm across at any yaw: a
    30 mm cube reaches 36.2 mm from its centre line, over the 10 mm gap onto the next belt; the
    bundled camera scenario's 80 mm belts 90 mm apart keep it on its own."""
    from ptint_drake.config.pick import BeltConfig, PickConfig
    from ptint_drake.worlds.pick.placement import bridging_warnings

    assert bridging_warnings(load_scenario("assembly_pick_place_rgbd").pick) == []
    belts = [BeltConfig(name="a", center=[0.30, 0.0, 0.1], width=0.04),
             BeltConfig(name="b", center=[0.25, 0.0, 0.1], width=0.04)]
    cube = PartConfig(belt="a", yaw_deg="random", lateral=[-0.015, 0.015])
    (line,) = bridging_warnings(PickConfig(belts=belts, parts=[cube]))
    assert line.startswith("pick.parts[0] (part)") and "36.2 mm" in line and "onto b" in line
    assert "its edge 30.0 mm" in line
    # at yaw 0 a cube 4 mm toward b reaches 19 mm: clear of it (30 mm); 15 mm away from b: clear
    assert bridging_warnings(PickConfig(belts=belts, parts=[PartConfig(belt="a", lateral=0.004)])) == []
    away = PartConfig(belt="a", lateral=-0.015, yaw_deg=45.0)
    assert bridging_warnings(PickConfig(belts=belts, parts=[away])) == []
    lower = [belts[0], BeltConfig(name="b", center=[0.25, 0.0, 0.0], width=0.04)]
    assert bridging_warnings(PickConfig(belts=lower, parts=[cube])) == []  # 100 mm below: not a bridge
