"""``StaticScene`` — parts at fixed poses on configured belts, seen by one RGB-D camera and the
perception: what the tests, the benchmark (``scripts/rgbd_bench.py``) and a check of a camera
placement use.  The parts' poses reach only the renderer (``PartGeometry``); the perception
reads the depth image alone."""

from __future__ import annotations

import time

import numpy as np
from pydrake.geometry import Box, Rgba, SceneGraph
from pydrake.math import RigidTransform
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource

from ptint_drake.config.measurement import RgbdCameraConfig
from ptint_drake.systems.perception.belt_regions import belt_regions
from ptint_drake.systems.perception.part_pose_estimator import MakeRgbdPerception, PerceptionConfig
from ptint_drake.systems.perception.rgbd_camera import AddRgbdCamera
from ptint_drake.systems.perception.scene_geometry import AddPartGeometry, visual_instance


class StaticScene:
    """``poses``: [(position (3), yaw (rad))] of the parts; ``camera``: the camera and belts
    (``camera.belts``), its shape and size the parts'; ``object_belts``: the belt each tracked
    object rides (default: one object per part, on belt 0)."""

    def __init__(self, camera: RgbdCameraConfig, poses, *, rate_hz: float = 30.0, latency: float = 0.033,
                 seed: int = 0, object_belts=None, perceive: bool = True, occluders=(),
                 check_above: bool = False):
        builder = DiagramBuilder()
        scene_graph = builder.AddNamedSystem("scene_graph", SceneGraph())
        belts = belt_regions(camera.belts)
        n = len(poses)
        positions = np.concatenate([np.asarray(p, float) for p, _ in poses]) if n else np.zeros(0)
        rotations = []
        for _, yaw in poses:
            c, s = np.cos(yaw), np.sin(yaw)
            rotations.extend([c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0])
        pos = builder.AddSystem(ConstantVectorSource(positions))
        rot = builder.AddSystem(ConstantVectorSource(np.asarray(rotations, float)))
        AddPartGeometry(builder, scene_graph, positions=pos.get_output_port(),
                        rotations=rot.get_output_port(), count=n, shape=camera.part_shape,
                        size=camera.part_size, belts=belts)
        if occluders:
            source = scene_graph.RegisterSource("occluders")
            for j, (box, centre) in enumerate(occluders):
                scene_graph.RegisterAnchoredGeometry(source, visual_instance(
                    RigidTransform(np.asarray(centre, float)), Box(*box), f"occluder_{j}",
                    Rgba(0.6, 0.6, 0.6, 1)))
        self.camera = AddRgbdCamera(builder, scene_graph, camera, rate_hz=rate_hz, seed=seed)
        self.perception = self.estimator = None
        if perceive:
            config = PerceptionConfig(self.camera.info, self.camera.X_WC, belts, camera.part_shape,
                                      list(camera.part_size), list(object_belts if object_belts is not None
                                                                   else [0] * n), rate_hz, latency,
                                      check_above)
            self.perception, self.estimator = MakeRgbdPerception(config)
            builder.AddSystem(self.perception)
            builder.Connect(self.camera.depth_image, self.perception.get_input_port())
        self.diagram = builder.Build()
        self.context = self.diagram.CreateDefaultContext()

    def depth(self, t: float = 0.0) -> np.ndarray:
        self.context.SetTime(t)
        sub = self.camera.noise.GetMyContextFromRoot(self.context)
        return np.array(self.camera.noise.get_output_port().Eval(sub).data)[:, :, 0]

    def color(self, t: float = 0.0) -> np.ndarray:
        self.context.SetTime(t)
        sub = self.camera.sensor.GetMyContextFromRoot(self.context)
        return np.array(self.camera.sensor.color_image_output_port().Eval(sub).data)

    def fits(self, t: float = 0.0) -> tuple[list, dict]:
        """The fits of the frame at t (and the time it took: render_s, cloud_s, fit_s)."""
        self.context.SetTime(t)
        sub = self.estimator.GetMyContextFromRoot(self.context)
        start = time.perf_counter()
        self.depth(t)
        rendered = time.perf_counter()
        cloud = self.estimator.GetInputPort("point_cloud").Eval(sub)
        clouded = time.perf_counter()
        fits = self.estimator.fit_frame(cloud)
        done = time.perf_counter()
        return fits, {"render_s": rendered - start, "cloud_s": clouded - rendered, "fit_s": done - clouded}
