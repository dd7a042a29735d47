"""Per-frame cost of the RGB-D camera and its perception (issue 34), printed as JSON.

``python scripts/rgbd_bench.py [scenario] [--frames N]`` (default ``conveyor_pair_rgbd``, 30
frames): the scenario's station (arm visuals, objects, belts, camera) and perception are built,
and for frames k = 1 … N (t = k / rate, the objects moving, the arm at its initial pose) the wall
time of each stage is measured separately: ``render_s`` (RgbdSensor's depth image on
RenderEngineVtk), ``noise_s`` (the D415-style DepthNoise), ``cloud_s`` (DepthImageToPointCloud),
``fit_s`` (crop, voxel grid, clustering and fits).  The first render (VTK's start-up) is reported
apart.  Also printed: the fits' position error against the objects' true motion (mm)."""

from __future__ import annotations

import argparse
import json
import platform
import time

import numpy as np

from ptint_drake.config.yaml_io import drake_version
from ptint_drake.simulation.scenario import load_scenario
from ptint_drake.worlds.interception.camera_frames import build_rgbd_view


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenario", nargs="?", default="conveyor_pair_rgbd")
    parser.add_argument("--frames", type=int, default=30)
    args = parser.parse_args()
    scenario = load_scenario(args.scenario)
    view = build_rgbd_view(scenario)
    station, estimator, context = view.station, view.estimator, view.context
    sensor = station.diagram.GetSubsystemByName("rgbd_camera")
    noise = station.diagram.GetSubsystemByName("rgbd_camera_depth_noise")
    cloud_port = estimator.GetInputPort("point_cloud")
    sub = lambda s: s.GetMyContextFromRoot(context)  # noqa: E731
    start = time.perf_counter()
    sensor.depth_image_32F_output_port().Eval(sub(sensor))
    first = time.perf_counter() - start
    stages = {"render_s": [], "noise_s": [], "cloud_s": [], "fit_s": []}
    errors = []
    for k in range(1, args.frames + 1):
        t = k / scenario.measurement.rate_hz
        context.SetTime(t)
        t0 = time.perf_counter()
        sensor.depth_image_32F_output_port().Eval(sub(sensor))
        t1 = time.perf_counter()
        noise.get_output_port().Eval(sub(noise))
        t2 = time.perf_counter()
        cloud = cloud_port.Eval(sub(estimator))
        t3 = time.perf_counter()
        fits = estimator.fit_frame(cloud)
        t4 = time.perf_counter()
        for name, dt in zip(stages, (t1 - t0, t2 - t1, t3 - t2, t4 - t3)):
            stages[name].append(dt)
        truths = [target.evaluate(t)[0:3] for target in station.true_targets]
        for fit in fits:
            if fit.ok:
                errors.append(1000 * min(np.linalg.norm(fit.position - x) for x in truths))
    c = scenario.measurement.camera
    print(json.dumps({
        "scenario": args.scenario, "frames": args.frames, "image": [c.width, c.height],
        "drake": drake_version(),
        "python": platform.python_version(), "machine": platform.machine(),
        "first_render_s": round(first, 4),
        **{f"{name}_median": round(float(np.median(v)), 4) for name, v in stages.items()},
        "total_per_frame_s_median": round(float(np.median(np.sum([v for v in stages.values()], axis=0))), 4),
        "fit_error_mm": {"median": round(float(np.median(errors)), 3), "max": round(float(np.max(errors)), 3),
                         "count": len(errors)} if errors else None,
    }, indent=1))


if __name__ == "__main__":
    main()
