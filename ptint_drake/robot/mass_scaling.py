"""The ``mass_xF`` plant variant: a copy of a parsed robot model with every mass scaled.

Drake has no setter for a body's *default* spatial inertia (``RigidBody`` takes it
when it is added), so a variant that must hold in any default context — the station
added to a user's diagram, simulated by the user's own ``Simulator`` — is built as a
copy of the parsed, not yet finalized plant: the same model instances, bodies (each
link's mass and rotational inertia × F, about the same centre of mass, i.e. the same
unit inertia), frames, joints (limits, damping, default positions) and actuators
(effort limit, gear ratio, rotor inertia × F), added in the same order, so the copy's
multibody tree and its arithmetic are those of the original.  Bodies added after the
copy (the payload) are not scaled.

The copy supports the joints an arm's URDF or SDFormat file declares: revolute,
prismatic and fixed; any other joint type is a ``ScenarioError`` naming
``plant.mass_scale``.
"""

from __future__ import annotations

from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import (BodyIndex, FixedOffsetFrame, FrameIndex, JointIndex, ModelInstanceIndex,
                                    PrismaticJoint, RevoluteJoint, SpatialInertia, WeldJoint)

from ptint_drake.config.errors import ScenarioError

_JOINTS = (RevoluteJoint, PrismaticJoint, WeldJoint)


def scaled_inertia(M: SpatialInertia, scale: float) -> SpatialInertia:
    """``M`` with its mass × ``scale`` about the same centre of mass (the same unit inertia,
    so the rotational inertia scales with the mass); massless bodies are returned as they are."""
    if not M.get_mass() > 0.0:
        return M
    return SpatialInertia(M.get_mass() * scale, M.get_com(), M.get_unit_inertia())


def scaled_copy(source: MultibodyPlant, scale: float) -> MultibodyPlant:
    """A new continuous, not finalized plant: ``source`` (parsed, not finalized) with every
    body's mass and inertia and every actuator's rotor inertia × ``scale``."""
    if source.is_finalized():
        raise ValueError("scaled_copy: the source plant must not be finalized")
    for i in range(source.num_joints()):
        joint = source.get_joint(JointIndex(i))
        if not isinstance(joint, _JOINTS):
            raise ScenarioError(f"plant.mass_scale: the model's joint {joint.name()!r} is a "
                                f"{type(joint).__name__}; scaling supports revolute, prismatic "
                                f"and fixed joints")
    plant = MultibodyPlant(time_step=source.time_step())
    for i in range(plant.num_model_instances(), source.num_model_instances()):
        plant.AddModelInstance(source.GetModelInstanceName(ModelInstanceIndex(i)))
    for i in range(1, source.num_bodies()):
        body = source.get_body(BodyIndex(i))
        plant.AddRigidBody(body.name(), body.model_instance(),
                           scaled_inertia(body.default_spatial_inertia(), scale))
    frames = _copy_frames(source, plant)
    for i in range(source.num_joints()):
        _copy_joint(source.get_joint(JointIndex(i)), plant, frames)
    for index in source.GetJointActuatorIndices():
        actuator = source.get_joint_actuator(index)
        copy = plant.AddJointActuator(actuator.name(), plant.get_joint(actuator.joint().index()),
                                      actuator.effort_limit())
        copy.set_default_gear_ratio(actuator.default_gear_ratio())
        copy.set_default_rotor_inertia(actuator.default_rotor_inertia() * scale)
    return plant


def _copy_frames(source: MultibodyPlant, plant: MultibodyPlant) -> dict:
    """Every frame of ``source`` in ``plant`` (body frames are there already; fixed offset
    frames are added on their body's frame at their pose in it); index → frame."""
    frames = {}
    for i in range(source.num_frames()):
        frame = source.get_frame(FrameIndex(i))
        body_frame = plant.get_body(frame.body().index()).body_frame()
        if frame.is_body_frame():
            frames[i] = body_frame
        else:
            frames[i] = plant.AddFrame(FixedOffsetFrame(
                frame.name(), body_frame, frame.GetFixedPoseInBodyFrame(), frame.model_instance()))
    return frames


def _copy_joint(joint, plant: MultibodyPlant, frames: dict) -> None:
    """``joint`` between the copies of its frames, with its limits, damping and default pose."""
    parent, child = frames[int(joint.frame_on_parent().index())], frames[int(joint.frame_on_child().index())]
    if isinstance(joint, WeldJoint):
        plant.AddJoint(WeldJoint(joint.name(), parent, child, joint.X_FM()))
        return
    kind, axis = ((RevoluteJoint, joint.revolute_axis()) if isinstance(joint, RevoluteJoint)
                  else (PrismaticJoint, joint.translation_axis()))
    copy = plant.AddJoint(kind(joint.name(), parent, child, axis, joint.position_lower_limit(),
                               joint.position_upper_limit(), joint.default_damping()))
    copy.set_velocity_limits(joint.velocity_lower_limits(), joint.velocity_upper_limits())
    copy.set_acceleration_limits(joint.acceleration_lower_limits(), joint.acceleration_upper_limits())
    copy.set_default_positions(joint.default_positions())


def scale_in_context(plant: MultibodyPlant, context, instance, scale: float) -> None:
    """The ``mass_xF`` variant of model ``instance`` set in ``context`` of a finalized plant:
    every body's mass and inertia (``scaled_inertia``) and every actuator's rotor inertia ×
    ``scale`` — for a world whose plant holds more than the arm (the pick station), where the
    controller is not told either."""
    if scale == 1.0:
        return
    for index in plant.GetBodyIndices(instance):
        body = plant.get_body(index)
        M = body.CalcSpatialInertiaInBodyFrame(context)
        if M.get_mass() > 0.0:
            body.SetSpatialInertiaInBodyFrame(context, scaled_inertia(M, scale))
    for index in plant.GetJointActuatorIndices(instance):
        actuator = plant.get_joint_actuator(index)
        actuator.SetRotorInertia(context, actuator.rotor_inertia(context) * scale)
