"""The scenario's ``pick`` block: the pick-and-place world and its tasks, as typed settings for
Drake's ``yaml_load_typed`` (plain dataclasses, lists of floats, every field's unit beside it).

World frame: the arm's base frame (z up).  A *belt* is a conveyor whose top surface is a slab
riding a prismatic joint (``worlds.pick.scene``); a *part* is a free box or cylinder resting on a
belt; the *tray* is a welded plate whose *slots* are place poses.  ``PickWorldConfig`` gathers
them with the plant's settings (Drake's ``MultibodyPlantConfig`` fields that matter here).  Each
task becomes six prescribed-time segments (``worlds.pick.tasks`` has the plan).
(No ``from __future__ import annotations`` here: ``yaml_load_typed`` reads the field types.)
"""

from dataclasses import dataclass, field
from typing import List, Optional, Union

from ptint_drake.config.line import LineConfig


@dataclass
class GripperConfig:
    """A parallel two-finger gripper welded at the arm's end-effector frame (defaults: the
    RV-M1's motor-operated hand as modelled in ``models/rvm1_gripper.sdf``; models/README.md
    gives the sources and assumptions).  The finger joints are Drake PD-controlled actuators
    (implicit in the discrete solver) whose effort limit is the grip force."""

    model: str = "rvm1_gripper"  # a bundled gripper (models/<name>.sdf) or a path to an SDFormat file
    max_force: float = 30.0  # N, per finger: the force limit (actuator effort limit)
    speed: float = 0.05  # m/s, per finger: how fast each jaw closes or opens
    kp: float = 20000.0  # N/m, stiffness of each finger's position servo
    kd: float = 40.0  # N·s/m, damping of each finger's position servo
    initial_opening: float = 0.06  # m, distance between the pads at t = 0 (0 … the stroke)


@dataclass
class BeltConfig:
    """A conveyor: a slab (its top surface is the belt) that translates along ``direction`` at
    ``speed``.  At t = 0 the slab's top-surface centre is at ``center``; over a run it moves
    speed · duration, so ``length`` must cover the parts' travel."""

    name: str = "belt"  # model-instance name of the belt
    center: List[float] = field(default_factory=lambda: [0.3, 0.0, 0.1])  # m, top-surface centre at t = 0
    # 1, horizontal unit vector of travel
    direction: List[float] = field(default_factory=lambda: [0.0, 1.0, 0.0])
    speed: float = 0.1  # m/s, along ``direction``
    length: float = 1.2  # m, along ``direction``
    width: float = 0.08  # m, across the belt
    thickness: float = 0.02  # m, of the slab
    friction: float = 0.8  # 1, Coulomb friction of the belt surface
    mass: float = 2.0  # kg, of the slab (it is speed-servoed, so it hardly matters)


@dataclass
class PartConfig:
    """A free rigid part, initially resting on its belt (centre above the belt surface by half
    its height) and turned by ``yaw_deg`` about the vertical."""

    name: str = "part"  # body and model-instance name
    belt: str = "belt"  # the belt it rests on at t = 0 (a BeltConfig.name)
    shape: str = "box"  # "box" or "cylinder" (axis vertical)
    # m, box [x, y, z] (x: across the fingers when grasped) or cylinder [diameter, height]
    size: List[float] = field(default_factory=lambda: [0.03, 0.03, 0.03])
    offset: float = 0.0  # m, along the belt from its centre at t = 0 (negative: upstream)
    # m, across the belt from its centre line at t = 0 (+: left of the travel); or [min, max]:
    # drawn uniformly from measurement.seed (random placement: needs a camera, worlds.pick.placement)
    lateral: Union[List[float], float] = 0.0
    # deg, rotation about the vertical at t = 0; or "random": drawn uniformly in [-180, 180)
    yaw_deg: Union[float, str] = 0.0
    offset_jitter: float = 0.0  # m, ± uniform jitter added to ``offset`` (random placement)
    mass: float = 0.1  # kg
    friction: float = 0.8  # 1, Coulomb friction coefficient of its surface (static = dynamic)


@dataclass
class SlotConfig:
    """A place pose on the tray: where a part's centre should come to rest."""

    offset: List[float] = field(default_factory=lambda: [0.0, 0.0])  # m, [x, y] from the tray centre
    yaw_deg: float = 0.0  # deg, the part's wanted yaw relative to the tray


@dataclass
class TrayConfig:
    """A plate welded to the world; its slots are poses on its top surface."""

    center: List[float] = field(default_factory=lambda: [0.0, 0.3, 0.1])  # m, top-surface centre
    yaw_deg: float = 0.0  # deg, about the vertical
    size: List[float] = field(default_factory=lambda: [0.2, 0.12, 0.01])  # m, [x, y, thickness]
    friction: float = 0.8  # 1, Coulomb friction of its surface
    slots: List[SlotConfig] = field(default_factory=list)


@dataclass
class BinConfig:
    """An open box welded to the world (a floor and four walls, ``scene.bin_boxes``): a part
    dropped into it from above its walls counts "in the bin" (no place pose, no mm criterion)."""

    name: str = "bin"  # body and model-instance name
    center: List[float] = field(default_factory=lambda: [0.15, 0.22, 0.10])  # m, its inner floor's centre
    size: List[float] = field(default_factory=lambda: [0.10, 0.10, 0.05])  # m, inner [x, y, depth]
    wall: float = 0.005  # m, the thickness of its walls and floor
    friction: float = 0.8  # 1, Coulomb friction of its surfaces


@dataclass
class PickWorldConfig:
    """Everything physical in a pick-and-place station besides the arm's own model file."""

    model: str = "rvm1_5dof"  # the arm: a bundled model name or a URDF/SDFormat path
    end_effector: str = "tool"  # the arm frame the gripper's fingertip centre is welded to
    initial_q_deg: List[float] = field(default_factory=lambda: [22.5, 45.0, 30.0, 15.0, 0.0])  # deg
    time_step: float = 0.001  # s, of the discrete plant
    # Drake's discrete contact approximation: "sap", "lagged" or "similar" (those of both
    # Drake 1.51 and 1.58; scripts/contact_bench.py measures them; "tamsi" only on Drake < 1.55)
    contact_approximation: str = "sap"
    # Drake's contact model: "point", "hydroelastic" or "hydroelastic_with_fallback"
    contact_model: str = "point"
    gripper: GripperConfig = field(default_factory=GripperConfig)
    belts: List[BeltConfig] = field(default_factory=list)
    parts: List[PartConfig] = field(default_factory=list)
    tray: TrayConfig = field(default_factory=TrayConfig)
    bins: List[BinConfig] = field(default_factory=list)


PHASES = ("approach", "descend", "lift", "carry", "place", "retreat")


@dataclass
class MoveConfig:
    """One prescribed-time segment of a task: its duration tf (s) and TBG shape β; where the plan
    splits the phase by a via (``worlds.pick.route``, ``worlds.pick.obstacles``), the share of tf
    the via's leg takes (``via_share``; None: the share its length takes of the two legs')."""

    tf: float = 1.0  # s
    beta: float = 0.75  # 1, in (0, 1)
    via_share: Optional[float] = None  # 1, in (0, 1), or None: by the legs' lengths


@dataclass
class PickTaskConfig:
    """One part picked off its belt and placed in one tray slot, dropped into one bin or put on an
    outgoing belt (see the module docstring): exactly one of ``slot``, ``bin`` and ``belt``."""

    part: str = ""  # the part's name (pick.parts[*].name)
    slot: Optional[int] = None  # index into pick.tray.slots
    bin: str = ""  # or the name of a bin (pick.bins[*].name): the part dropped into it
    # m, (x, y): where over the bin's floor, from its centre (a line spreads its drops, ``scene.bin_spots``)
    bin_at: List[float] = field(default_factory=lambda: [0.0, 0.0])
    belt: str = ""  # or an outgoing belt (pick.belts[*].name): the part put on it, riding it
    belt_at: float = 0.0  # m, the place point's coordinate along that belt at t = 0 (it rides on)
    start: float = 0.0  # s, the approach's start (0: right after the previous task)
    approach: MoveConfig = field(default_factory=lambda: MoveConfig(1.2))
    descend: MoveConfig = field(default_factory=lambda: MoveConfig(0.5))
    lift: MoveConfig = field(default_factory=lambda: MoveConfig(0.4))
    carry: MoveConfig = field(default_factory=lambda: MoveConfig(1.2))
    place: MoveConfig = field(default_factory=lambda: MoveConfig(0.5))
    retreat: MoveConfig = field(default_factory=lambda: MoveConfig(0.4))
    clearance: float = 0.04  # m, of the pre-grasp pose above the part and of the retreat
    lift_height: float = 0.05  # m, of the lift and the carry
    dwell: float = 0.15  # s, the grip building up after the close, and the fingers opening
    margin: float = 0.012  # m, the open fingers' clearance around the part (opening − width)
    close_delay: float = 0.0  # s, added to the close command's time (negative: early; robust's jitter)
    # rad (world), a line's decision (``line.cycle``): the yaw the top-down tool grips at — the part's
    # symmetric yaw nearest it (a cylinder: this yaw) — and its yaw at the slot (None: the part's x
    # axis and the slot's yaw, each modulo π)
    grip_yaw: Optional[float] = None
    place_yaw: Optional[float] = None
    # a retry's first segment: the tool rises ``clearance`` above where the part is while the
    # fingers open (then a new approach and descend, with this task's tf and β)
    backoff: MoveConfig = field(default_factory=lambda: MoveConfig(0.3))


@dataclass
class PickConfig:
    """The scenario's ``pick`` block: the physical world and the tasks."""

    gripper: GripperConfig = field(default_factory=GripperConfig)
    belts: List[BeltConfig] = field(default_factory=list)
    parts: List[PartConfig] = field(default_factory=list)
    tray: TrayConfig = field(default_factory=TrayConfig)
    bins: List[BinConfig] = field(default_factory=list)
    tasks: List[PickTaskConfig] = field(default_factory=list)
    # the confirmed grasp (``systems.hand.gripper.GraspObserver``, docs/pick_place.md "Grasp states"):
    retries: int = 1  # new approach + descend after an empty grasp or a timeout (0: none)
    grasp_window: float = 0.3  # s after the prescribed grasp time: the latest the lift waits for ``holding``
    width_tolerance: float = 0.003  # m, ``holding``: the opening within the part's width ± this
    # TEST OPTION (leave 0): send the first attempt's close command this much earlier, so that
    # "closed on nothing" is reproducible (e.g. 0.3: the arm holds its pre-grasp pose until the
    # fingers have closed above the part, ``pick.tasks._closed_on_nothing``; negative: later, a late grasp)
    test_close_advance_s: float = 0.0
    # a line that runs itself (issue 44, ``config.line``): parts arrive, the arm decides; None: the tasks
    line: Optional[LineConfig] = None


