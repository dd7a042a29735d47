"""The ``pick.line`` block (issue 44): a line that runs itself — parts arrive unannounced on the
declared belts and the arm decides online what to pick (``worlds.pick.line``).

A line scenario declares the cell, not a script: ``pick.belts`` and ``pick.tray`` as any pick
scenario, no ``pick.parts`` and no ``pick.tasks`` (the run makes them), and this block:

- ``belts``: the belts the line uses, by name, each with or without an ``encoder`` (with one the
  controller side reads the belt's measured speed; without, only its declared ``speed``);
- ``catalog``: the kinds of part (shape, size, mass, friction) and where each goes: the tray
  ``slots`` it fills (``fill``: the free one of the shorter cycle, or in order), a ``bin`` of
  ``pick.bins`` it is dropped into (which never fills: "in the bin", no mm criterion), or an
  outgoing ``belt`` of ``pick.belts`` it is put on, riding it (``worlds.pick.out_belt``: "on the
  belt", no mm criterion);
- ``arrivals``: per belt, parts per second (a rate, not a spacing: a faster belt does not bring
  more parts), the process (``poisson`` or ``jittered``), the distributions of the lateral offset
  and the yaw, the kinds' mix;
- ``speed_steps``: changes of a belt's speed at a time (``t: 0``: from the start), which the
  controller side is not told of;
- ``truth``: what the pool's parts are where they differ from their kind, which the controller
  side is not told of either (``PoolTruthConfig``: the robust study's per-part draws);
- ``seed``: of the arrival process.

The scenario's ``duration`` is the line's.  Plain dataclasses for Drake's ``yaml_load_typed`` (no
postponed annotations: it reads the field types); the checks are ``check_line``.
"""

from dataclasses import dataclass, field
from typing import Dict, List

import numpy as np

from ptint_drake.config.errors import ScenarioError
from ptint_drake.config.part_shape import check_part_shape

PROCESSES = ("poisson", "jittered")
FILLS = ("cycle", "order")  # how a kind's free tray slot is chosen (``KindConfig.fill``)


@dataclass
class LineBeltConfig:
    """A belt of the line (a ``pick.belts[*].name``) and whether it has an encoder."""

    name: str = ""
    encoder: bool = False  # the controller side reads its measured speed (else its declared one)


@dataclass
class KindConfig:
    """A kind of part of the catalog and where it goes: its tray ``slots``, a ``bin`` (the name of
    one of ``pick.bins``) or an outgoing ``belt`` (the name of one of ``pick.belts`` that no
    arrival feeds) — exactly one of the three.  ``fill``: which free slot a pick takes — ``cycle``
    (of the two free slots nearest the grasp, the one whose pick cycle the min-tf model finds
    shorter: ``worlds.pick.line.slot_choice``) or ``order`` (the first free one as listed: a kit
    filled in a set order)."""

    name: str = "cube"
    shape: str = "box"  # "box" or "cylinder" (axis vertical)
    size: List[float] = field(default_factory=lambda: [0.03, 0.03, 0.03])  # m, box [x, y, z] / [d, h]
    mass: float = 0.1  # kg
    friction: float = 0.8  # 1, Coulomb friction of its surface
    slots: List[int] = field(default_factory=list)  # indices into pick.tray.slots
    bin: str = ""  # or the name of a bin (pick.bins[*].name): every part of the kind dropped into it
    belt: str = ""  # or an outgoing belt (pick.belts[*].name): every part of the kind put on it
    fill: str = "cycle"  # "cycle" (the free slot of the shorter cycle) or "order" (as listed)


@dataclass
class ArrivalConfig:
    """The arrival process of one belt: ``rate`` parts per second from ``start`` until
    ``until`` s before the scenario's end (the drain: a part released later could not be picked
    by the end — at 0.1 m/s about 4 s to the reach, 1.7 s to the grasp, a 4.5 s cycle; measured
    with 8 s: the last parts counted ``on the belt at the end``).  Each part is put on the belt
    ``release`` m along it from its centre (negative: upstream); ``lateral`` and ``yaw_deg``
    drawn uniformly in [min, max]; its kind drawn by the ``mix`` weights (empty: every kind of
    the catalog alike).

    ``poisson``: gaps of ``min_gap`` + an exponential of mean 1/rate − ``min_gap`` (a Poisson
    process with a dead time: the mean rate kept); ``jittered``: gaps of 1/rate × (1 ± ``jitter``)
    (uniform), at least ``min_gap``.  ``min_gap``: no part is put where the previous one may still
    be (the gap × the belt speed apart, centre to centre).  Whatever the gap, a part is released
    only once its belt has carried the one before it the two parts' footprint radii and 5 mm on
    (``worlds.pick.line.arrivals.spaced``: on a slow belt ``min_gap`` alone is too short)."""

    belt: str = ""
    rate: float = 0.2  # parts/s
    process: str = "poisson"
    jitter: float = 0.3  # 1, of the period (jittered only)
    min_gap: float = 0.6  # s
    start: float = 0.0  # s, the earliest release
    until: float = 12.0  # s, before the scenario's end: the last release
    release: float = -0.6  # m, along the belt from its centre at t = 0
    lateral: List[float] = field(default_factory=lambda: [0.0, 0.0])  # m, [min, max]
    yaw_deg: List[float] = field(default_factory=lambda: [-180.0, 180.0])  # deg, [min, max]
    mix: Dict[str, float] = field(default_factory=dict)  # kind name → weight


@dataclass
class SpeedStepConfig:
    """The belt ``belt`` runs at ``factor`` × its declared speed from ``t`` on (truth only)."""

    belt: str = ""
    t: float = 0.0  # s (0: from the start)
    factor: float = 1.0


@dataclass
class PoolTruthConfig:
    """The truth of the pool's parts (release order, ``line.arrivals``) where it differs from their
    catalog kind; an empty list: the kind's.  The controller side reads the catalog (its object
    model), never these.  ``lateral`` is added to the drawn offset (clipped to the belt's half
    width); ``close_delay`` (s) to the close command of every task that picks the part (the
    actuation's jitter, ``PickTaskConfig.close_delay``).  ``ptint robust`` fills them."""

    mass: List[float] = field(default_factory=list)  # kg per pool part
    friction: List[float] = field(default_factory=list)  # 1 per pool part
    lateral: List[float] = field(default_factory=list)  # m per pool part
    close_delay: List[float] = field(default_factory=list)  # s per pool part


@dataclass
class LineConfig:
    """The ``pick.line`` block (module docstring)."""

    belts: List[LineBeltConfig] = field(default_factory=list)
    catalog: List[KindConfig] = field(default_factory=list)
    arrivals: List[ArrivalConfig] = field(default_factory=list)
    speed_steps: List[SpeedStepConfig] = field(default_factory=list)
    truth: PoolTruthConfig = field(default_factory=PoolTruthConfig)
    seed: int = 0
    decide_period: float = 0.1  # s, between the scheduler's looks while the arm is free
    redecide_mm: float = 10.0  # mm, the predicted grasp point's drift that calls a new decision

    def kind(self, name: str) -> KindConfig:
        """The catalog's kind named ``name`` (a track's class, a pool part's kind); KeyError when
        none is (the scenario checks refuse an arrival ``mix`` naming no kind)."""
        for kind in self.catalog:
            if kind.name == name:
                return kind
        raise KeyError(f"pick.line.catalog: no kind named {name!r}")


def _pair(values: list, where: str) -> None:
    if len(values) != 2 or not values[0] <= values[1] or not np.all(np.isfinite(values)):
        raise ScenarioError(f"{where}: [min, max] with min <= max, got {values}")


def _check_kind(k: int, kind: KindConfig, slots: int, bins: list, outgoing: dict) -> None:
    where = f"pick.line.catalog[{k}]"
    check_part_shape(where, kind.shape, kind.size, kind.mass, kind.friction)
    if kind.belt:
        if kind.slots or kind.bin:
            raise ScenarioError(f"{where}.belt: a kind goes to its slots, a bin or an outgoing belt: "
                                f"exactly one")
        if kind.belt not in outgoing:
            raise ScenarioError(f"{where}.belt: no belt named {kind.belt!r} in pick.belts")
        if outgoing[kind.belt] is None:
            raise ScenarioError(f"{where}.belt: belt {kind.belt!r} is fed by pick.line.arrivals: an "
                                f"outgoing belt takes no arrivals")
        return
    if kind.bin:
        if kind.slots:
            raise ScenarioError(f"{where}.bin: a kind goes to its slots or to a bin, not both")
        if kind.bin not in bins:
            raise ScenarioError(f"{where}.bin: no bin named {kind.bin!r} in pick.bins")
        return
    if kind.fill not in FILLS:
        raise ScenarioError(f"{where}.fill: {kind.fill!r} is not one of {', '.join(FILLS)}")
    if not kind.slots or any(not 0 <= j < slots for j in kind.slots):
        raise ScenarioError(f"{where}.slots: tray slots 0 … {slots - 1} for this kind, got {kind.slots}")


def _check_arrival(k: int, arrival: ArrivalConfig, belts: dict, kinds: set, duration: float) -> None:
    where = f"pick.line.arrivals[{k}]"
    if arrival.belt not in belts:
        raise ScenarioError(f"{where}.belt: no line belt named {arrival.belt!r} (pick.line.belts)")
    if arrival.process not in PROCESSES:
        raise ScenarioError(f"{where}.process: {arrival.process!r} is not one of {', '.join(PROCESSES)}")
    if not 0.0 < arrival.rate <= 10.0:
        raise ScenarioError(f"{where}.rate: parts per second in (0, 10], got {arrival.rate}")
    if not 0.0 <= arrival.jitter < 1.0 or arrival.min_gap < 0.0:
        raise ScenarioError(f"{where}.{'jitter' if arrival.min_gap >= 0.0 else 'min_gap'}: out of range")
    if not 0.0 <= arrival.start < duration - arrival.until:
        raise ScenarioError(f"{where}.start: {arrival.start} s leaves no time to release before "
                            f"duration − until = {duration - arrival.until:g} s")
    belt = belts[arrival.belt]
    if abs(arrival.release) > belt.length / 2:
        raise ScenarioError(f"{where}.release: {arrival.release} m is off its belt (length {belt.length} m)")
    _pair(arrival.lateral, f"{where}.lateral")
    _pair(arrival.yaw_deg, f"{where}.yaw_deg")
    if max(abs(v) for v in arrival.lateral) > belt.width / 2:
        raise ScenarioError(f"{where}.lateral: {arrival.lateral} m puts parts off the belt "
                            f"(width {belt.width} m)")
    for name, weight in arrival.mix.items():
        if name not in kinds or not weight >= 0.0:
            raise ScenarioError(f"{where}.mix: {name!r}: {weight} is not a catalog kind with a weight >= 0")


def check_line(pick, duration: float, stroke: float, margin: float) -> None:
    """ScenarioError naming the first bad field of ``pick.line`` (``pick``: the scenario's ``pick``
    block; ``stroke``: the gripper's largest opening, m): unknown belts and kinds, a kind wider
    than the stroke less ``margin`` (the tasks' open-finger clearance: the fingers would not
    pass it)."""
    line = pick.line
    if pick.parts or pick.tasks:
        raise ScenarioError("pick.parts: a line makes its parts and tasks (pick.line): leave pick.parts "
                            "and pick.tasks out")
    declared = {b.name: b for b in pick.belts}
    for k, belt in enumerate(line.belts):
        if belt.name not in declared:
            raise ScenarioError(f"pick.line.belts[{k}].name: no belt named {belt.name!r} in pick.belts")
    if not line.catalog:
        raise ScenarioError("pick.line.catalog: at least one kind of part is needed")
    for k, kind in enumerate(line.catalog):
        fed = {a.belt for a in line.arrivals}
        outgoing = {name: (None if name in fed else b) for name, b in declared.items()}
        _check_kind(k, kind, len(pick.tray.slots), [b.name for b in pick.bins], outgoing)
        if kind.size[0] + margin > stroke:
            raise ScenarioError(f"pick.line.catalog[{k}].size: {kind.size[0]} m across the fingers + the "
                                f"{margin} m margin exceeds the gripper's {stroke} m stroke")
    if len({k.name for k in line.catalog}) != len(line.catalog):
        raise ScenarioError("pick.line.catalog: kind names must be unique")
    if not line.arrivals:
        raise ScenarioError("pick.line.arrivals: at least one arrival process is needed")
    belts = {b.name: declared[b.name] for b in line.belts}
    for k, arrival in enumerate(line.arrivals):
        _check_arrival(k, arrival, belts, {c.name for c in line.catalog}, duration)
    for k, step in enumerate(line.speed_steps):
        if step.belt not in belts:
            raise ScenarioError(f"pick.line.speed_steps[{k}].belt: no line belt named {step.belt!r}")
        if not (0.0 <= step.t < duration and 0.0 <= step.factor <= 5.0):
            raise ScenarioError(f"pick.line.speed_steps[{k}]: t in [0, duration) and factor in [0, 5], "
                                f"got t {step.t}, factor {step.factor}")
    if not (0.02 <= line.decide_period <= 1.0 and line.redecide_mm > 0.0):
        raise ScenarioError("pick.line.decide_period: in [0.02, 1] s (and redecide_mm > 0)")
