"""Issue 43, the perception in a process of its own on the drive side
(``systems.perception.frame_process``): a frame fitted in the worker process and written into
the estimator when its sample is due leaves the estimator exactly as its own update at the
frame's time does (the bundled camera pick's station, its first frame, handed over as its LCM
message); a frame fitted ahead is written without a wait; submitting a frame does not wait for
its fit; and a frame the worker cannot read is one line (``FrameError``)."""

from __future__ import annotations

import sys
import time

import numpy as np
import pytest
from pydrake.common.value import AbstractValue
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import PassThrough
from pydrake.systems.sensors import ImageDepth32F

from ptint_drake.hardware.camera_link import pack_depth_image
from ptint_drake.hardware.drive import FRAME_DECODER
from ptint_drake.simulation.scenario import load_scenario
from ptint_drake.systems.perception.frame_process import FrameError, FrameProcess
from ptint_drake.worlds.base import new_simulator
from ptint_drake.worlds.pick.camera import AddPartEstimates
from ptint_drake.worlds.pick.cell import world_config
from ptint_drake.worlds.pick.station import MakePickStation

RGBD_PICK = "conveyor_pick_place_rgbd"
CONFIRM_FRAMES = 3  # frames until a track is confirmed and its part gets samples (``tracks``)


def _first_frame(scenario):
    """The station's depth image at t = 0 (the part on its belt, in view)."""
    station = MakePickStation(world_config(scenario), scenario.measurement)
    context = station.diagram.CreateDefaultContext()
    station.start_running(station.plant.GetMyMutableContextFromRoot(context))
    rendered = station.diagram.GetOutputPort("depth_image").Eval(context)
    image = ImageDepth32F(rendered.width(), rendered.height())
    image.mutable_data[:] = rendered.data
    return image


def _estimator(scenario, elsewhere: bool):
    builder = DiagramBuilder()
    depth = builder.AddNamedSystem("depth", _PassImage())
    estimates = AddPartEstimates(builder, depth.get_output_port(), scenario, fits_elsewhere=elsewhere)
    builder.ExportInput(depth.get_input_port(), "depth_image")
    return builder.Build(), estimates


def _PassImage():
    return PassThrough(AbstractValue.Make(ImageDepth32F()))


def _state(estimates, context) -> list:
    sub = estimates.estimator.GetMyContextFromRoot(context)
    return [np.array(sub.get_discrete_state(i).value()) for i in range(sub.num_discrete_state_groups())]


def test_a_frame_fitted_in_the_worker_leaves_the_estimator_as_its_own_update():
    scenario = load_scenario(RGBD_PICK)
    image = _first_frame(scenario)
    latency, period = scenario.measurement.latency, 1.0 / scenario.measurement.rate_hz
    times = [k * period for k in range(CONFIRM_FRAMES)]
    # the one-process way: the estimator's updates at t_k fit the frames (a track is confirmed,
    # and its part's sample buffered, at its third: ``tracks``)
    diagram, estimates = _estimator(scenario, elsewhere=False)
    simulator = new_simulator(diagram)
    diagram.GetInputPort("depth_image").FixValue(simulator.get_mutable_context(), image)
    simulator.AdvanceTo(times[-1] + latency)
    expected = _state(estimates, simulator.get_context())
    assert expected[0].any()  # the frames' sample is in the buffer (the part was fitted and tracked)
    # the drive's way: each frame's message as received to the worker, written when due
    diagram, estimates = _estimator(scenario, elsewhere=True)
    frames = FrameProcess(estimates.estimator, estimates.config, 1e-3)
    try:
        frames.start(decoder=FRAME_DECODER)
        simulator = new_simulator(diagram)
        start = time.perf_counter()
        frames.submit(0.0, pack_depth_image(0.0, image, "camera"), handshake=True)
        handed = time.perf_counter() - start
        frames.prefetch()
        frames.take_due(simulator.get_mutable_context(), latency - 1e-3)  # not due yet: not written
        assert not _state(estimates, simulator.get_context())[0].any()
        for t in times[1:]:
            frames.submit(t, pack_depth_image(t, image, "camera"))
        frames.prefetch()  # the fits back before they are due, as in real time (the latency)
        for t in times:
            frames.take_due(simulator.get_mutable_context(), t + latency)
            simulator.AdvanceTo(t + latency)
        got = _state(estimates, simulator.get_context())
        bad = times[-1] + period
        frames.submit(bad, b"not an image message")  # the next frame, unreadable
        frames.prefetch()  # its answer back before it is due too (the loop's wait is what is checked)
        with pytest.raises(FrameError, match="camera frame rejected"):
            frames.take_due(simulator.get_mutable_context(), bad + latency)
    finally:
        summary = frames.close()
    for a, b in zip(expected, got, strict=True):
        assert np.array_equal(a, b)
    # handing the frame over is a copy, not the fit; the fit was back before it was due
    assert handed < summary["fit_ms"]["max"] * 1e-3, (handed, summary)
    assert summary["wait_ms"]["max"] < 1.0, summary


@pytest.mark.skipif(sys.version_info < (3, 11), reason="PYTHONSAFEPATH is Python >= 3.11's")
def test_the_worker_runs_this_package_from_a_folder_holding_another(tmp_path, monkeypatch):
    """``python -m`` puts the working folder first: from a folder holding a ``ptint_drake`` (a source
    tree beside a non-editable install) the worker imported that one (``FrameProcess.start``)."""
    decoy = tmp_path / "ptint_drake"
    decoy.mkdir()
    (decoy / "__init__.py").write_text("raise ImportError('the decoy ptint_drake was imported')\n")
    monkeypatch.chdir(tmp_path)
    _, estimates = _estimator(load_scenario(RGBD_PICK), elsewhere=True)
    frames = FrameProcess(estimates.estimator, estimates.config, 1e-3)
    try:
        frames.start(decoder=FRAME_DECODER)  # (a worker that imported the decoy never says ready)
    finally:
        frames.close()
