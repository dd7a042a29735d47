"""The catch world's ball and the air it flies through (issue 46).

The ball is ``models/catch_ball.sdf``: a 65 mm, 40 g foam sphere (models/README.md, "The catch
ball", gives the sources).  ``AddBall`` parses it into a plant as a free body.

``AirDrag`` is the truth side's quadratic air drag F = −½ ρ C_d A |v| v on the ball's centre, an
``ExternallyAppliedSpatialForce`` list for the plant's ``applied_spatial_force`` input: the
estimators' ballistic model has no drag, so it is not exact.  ``DRAG_CD`` (a smooth sphere's
subcritical C_d) and ``AIR_DENSITY`` (dry air at 20 °C) are cited in models/README.md.

``restitution`` is the drop test: the ball falls from a height onto a rigid floor in a discrete
plant with point contact and the given contact approximation, and the coefficient of restitution
is the rebound speed over the impact speed (first contact).  SAP has no restitution coefficient
and ignores ``hunt_crossley_dissipation`` (measured: the same rebound for 0.5, 2 and 5 s/m); its
dissipation is the ``relaxation_time``, which the SDF sets so that e = 0.50 at a 1 ms step from
0.5 m.  The Hunt–Crossley dissipation (0.12 s/m) gives the same e with the ``similar`` and
``lagged`` approximations.
"""

from __future__ import annotations

import numpy as np
from pydrake.geometry import AddContactMaterial, HalfSpace, ProximityProperties
from pydrake.math import RigidTransform
from pydrake.multibody.math import SpatialForce, SpatialVelocity
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import (AddMultibodyPlant, CoulombFriction, ExternallyAppliedSpatialForce,
                                     MultibodyPlant, MultibodyPlantConfig)
from pydrake.multibody.tree import RigidBody
from pydrake.common.value import AbstractValue
from pydrake.systems.framework import DiagramBuilder, LeafSystem

from ptint_drake.robot.rvm1 import model_path
from ptint_drake.worlds.base import new_simulator

BALL_DIAMETER = 0.065  # m
BALL_MASS = 0.040  # kg
DRAG_CD = 0.47  # smooth sphere, Re ~ 1e4-1e5 (subcritical)
AIR_DENSITY = 1.204  # kg/m³, dry air at 20 °C, 101.325 kPa
TARGET_RESTITUTION = 0.5  # the foam ball's coefficient of restitution on a rigid floor (assumed)


def ball_path():
    """The ball's SDFormat file (installed with the models)."""
    return model_path().parent / "catch_ball.sdf"


def drag_coefficient() -> float:
    """k of the drag force −k |v| v (kg/m): ½ ρ C_d π r²."""
    return 0.5 * AIR_DENSITY * DRAG_CD * np.pi * (BALL_DIAMETER / 2) ** 2


def AddBall(plant: MultibodyPlant) -> RigidBody:
    """The ball parsed into ``plant`` (not finalized) in its own model instance; its body."""
    (instance,) = Parser(plant, "ball").AddModels(str(ball_path()))
    return plant.GetBodyByName("ball", instance)


class AirDrag(LeafSystem):
    """Quadratic air drag on one body (module docstring).  Input ``body_spatial_velocities`` (the
    plant's port of that name); output ``force``: a one-element list of
    ``ExternallyAppliedSpatialForce`` at the body's origin (the ball's centre), world frame."""

    def __init__(self, body: RigidBody, k: float = None):
        super().__init__()
        self._index = body.index()
        self._k = drag_coefficient() if k is None else float(k)
        self.DeclareAbstractInputPort("body_spatial_velocities",
                                      AbstractValue.Make([SpatialVelocity()]))
        self.DeclareAbstractOutputPort("force", lambda: AbstractValue.Make([ExternallyAppliedSpatialForce()]),
                                       self._force)

    def _force(self, context, output) -> None:
        v = self.get_input_port().Eval(context)[int(self._index)].translational()
        applied = ExternallyAppliedSpatialForce()
        applied.body_index = self._index
        applied.p_BoBq_B = np.zeros(3)
        applied.F_Bq_W = SpatialForce(np.zeros(3), -self._k * np.linalg.norm(v) * v)
        output.set_value([applied])


def AddAirDrag(builder: DiagramBuilder, plant: MultibodyPlant, body: RigidBody) -> AirDrag:
    """``AirDrag`` on ``body``, wired to ``plant``'s velocities and applied-force input."""
    drag = builder.AddNamedSystem("air_drag", AirDrag(body))
    builder.Connect(plant.get_body_spatial_velocities_output_port(), drag.get_input_port())
    builder.Connect(drag.get_output_port(), plant.get_applied_spatial_force_input_port())
    return drag


def restitution(time_step: float = 1e-3, height: float = 0.5, approximation: str = "sap") -> float:
    """The drop test (module docstring): e = rebound speed / impact speed of the ball dropped from
    ``height`` (m, its lowest point) onto a rigid floor."""
    builder = DiagramBuilder()
    plant, _ = AddMultibodyPlant(MultibodyPlantConfig(
        time_step=time_step, contact_model="point", discrete_contact_approximation=approximation), builder)
    body = AddBall(plant)
    floor = ProximityProperties()
    AddContactMaterial(dissipation=0.0, point_stiffness=1e7, friction=CoulombFriction(0.8, 0.8),
                       properties=floor)
    floor.AddProperty("material", "relaxation_time", 0.0)
    plant.RegisterCollisionGeometry(plant.world_body(), RigidTransform(), HalfSpace(), "floor", floor)
    plant.Finalize()
    simulator = new_simulator(builder.Build())
    context = plant.GetMyMutableContextFromRoot(simulator.get_mutable_context())
    r = BALL_DIAMETER / 2
    plant.SetFreeBodyPose(context, body, RigidTransform([0.0, 0.0, height + r]))
    impact, before, t = None, 0.0, 0.0
    while t < 2.0:
        t += time_step
        simulator.AdvanceTo(t)
        z = plant.EvalBodyPoseInWorld(context, body).translation()[2]
        vz = plant.EvalBodySpatialVelocityInWorld(context, body).translational()[2]
        if z < r and impact is None:
            impact = before
        elif z >= r and impact is not None:
            return float(-vz / impact)
        before = vz
    raise RuntimeError("the ball did not rebound within 2 s")
