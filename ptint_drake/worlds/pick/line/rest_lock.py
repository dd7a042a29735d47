"""Parts at rest in a static place locked, and unlocked when anything moving comes near (issue 44's
CPU budget: a part resting in contact costs the SAP solver 0.09–0.15 CPU ms a 1 ms step,
``scripts/sample_cpu.py --plant``; a placed part would keep costing that in its slot to the end).

The truth side's rule (``truth.LineTruth`` applies it at its stops):

- **Lock.**  A released part that is not on a belt (``truth.on_belt``: riding a slab, which moves)
  and not parked, whose speed is below ``REST_SPEED`` and turn rate below ``REST_RATE`` at two of
  the truth's checks at least ``REST_TIME`` apart, with nothing moving within ``margin`` of it
  (below), has its floating joint locked (Drake's ``Joint.Lock``, as a parked part is: the
  discrete solver holds its velocity at 0 and spends no contact work on it).  A part in a slot of
  the tray, in a bin or at rest on the floor: each lies on something welded to the world.
- **Unlock.**  At every check while a part is locked, the signed distance (Drake's
  ``QueryObject.ComputeSignedDistancePairClosestPoints``, geometry by geometry) from its collision
  geometry to every *moving* body's — every body of the arm and the gripper, and every released
  part not parked and not locked (a held part, a part riding a belt) — is measured; below
  ``margin`` the joint is unlocked (its velocity 0: the part is at rest there) and the contact
  solver has it again before anything can touch it.  Touching geometry (a pair whose distance
  query fails, e.g. two boxes in contact) counts as 0.
- **Checks.**  The truth's own stops (``RESET_PERIOD``) and the run's; while a part is locked a
  check every ``CHECK_PERIOD`` on top (``stops``), so that between two checks nothing moves more
  than ``V_BOUND`` × ``CHECK_PERIOD``: ``margin`` = ``CLEARANCE`` + that, with the moving bodies'
  measured speed at the check instead of ``V_BOUND`` when it is larger (×2: a runaway arm).

Choices the issue leaves open, made here: ``V_BOUND`` 1.5 m/s — above the largest speed of any
point of the arm, the gripper or a held part in the harsh line runs (measured: the tool's peak in
``line_assembly`` seeds 0–5 is below 1 m/s, ``tests/unit/test_line_rest_lock.py`` asserts the bound
over a run); ``REST_TIME`` 0.2 s; ``CLEARANCE`` 10 mm.  A locked part keeps its pose to the bit
while locked; unlocked it rests as before, so a placement measured at the end moves by what the
resting creep of SAP would have moved it (µm; ``docs/pick_place.md``, the harsh study).
"""

from __future__ import annotations

import numpy as np

REST_SPEED = 1e-3  # m/s
REST_RATE = 0.02  # rad/s
REST_TIME = 0.2  # s between the two checks that see a part at rest before it is locked
CHECK_PERIOD = 0.1  # s between the unlock checks while a part is locked
V_BOUND = 1.5  # m/s, the bound on any moving body's speed between two checks (module docstring)
CLEARANCE = 0.01  # m


def at_rest(plant, pc, body) -> bool:
    """A free body's speed below ``REST_SPEED`` and its turn rate below ``REST_RATE``."""
    V = plant.EvalBodySpatialVelocityInWorld(pc, body)
    return bool(np.linalg.norm(V.translational()) < REST_SPEED and np.linalg.norm(V.rotational()) < REST_RATE)


class RestLock:
    """The lock and unlock rule of the truth side (module docstring) on one station's plant;
    ``locked``: part → the time it was locked; ``log``: every ("lock" | "unlock", part, t)."""

    def __init__(self, station):
        self.locked: dict = {}
        self.log: list = []
        self._resting: dict = {}  # part → the first check it was seen at rest (s)
        self.rebind(station)

    def rebind(self, station) -> None:
        """The geometry of a rebuilt station's plant (the same bodies, new ids)."""
        self.station, plant = station, station.plant
        welded = {b.index() for b in plant.GetBodiesWeldedTo(plant.world_body())}  # (the arm's base)
        self._bodies = [plant.get_body(b) for m in (station.arm, station.gripper)
                        for b in plant.GetBodyIndices(m) if b not in welded]
        self._robot = [g for b in self._bodies for g in plant.GetCollisionGeometriesForBody(b)]
        self._parts = [plant.GetCollisionGeometriesForBody(b) for b in station.parts]

    def _joint(self, k: int):
        plant = self.station.plant
        (index,) = plant.GetJointIndices(self.station.parts[k].model_instance())
        return plant.get_joint(index)

    def stops(self, t_now: float, duration: float) -> list[float]:
        """The checks while a part is locked: every ``CHECK_PERIOD`` after ``t_now``."""
        if not self.locked:
            return []
        grid = np.arange(np.floor(t_now / CHECK_PERIOD) + 1, np.floor(duration / CHECK_PERIOD) + 1)
        return (grid * CHECK_PERIOD).round(9).tolist()

    def check(self, pc, t: float, free: list, on_belt) -> None:
        """At a check ``t``: unlock what something moving nears, then lock what rests.  ``free``:
        the released parts not parked; ``on_belt(k)``: part k rides a belt."""
        plant, parts = self.station.plant, self.station.parts
        moving = [k for k in free if k not in self.locked]
        speed = max([np.linalg.norm(plant.EvalBodySpatialVelocityInWorld(pc, b).translational())
                     for b in self._bodies]
                    + [np.linalg.norm(plant.EvalBodySpatialVelocityInWorld(pc, parts[k]).translational())
                       for k in moving])
        margin = CLEARANCE + max(V_BOUND, 2.0 * speed) * CHECK_PERIOD
        movers = self._robot + [g for k in moving for g in self._parts[k]]
        query = None
        for k in list(self.locked):
            query = query or plant.get_geometry_query_input_port().Eval(pc)
            if self._near(query, self._parts[k], movers, margin):
                self._joint(k).Unlock(pc)
                del self.locked[k]
                self._resting.pop(k, None)
                self.log.append(("unlock", k, t))
        for k in moving:
            if k in self.locked:
                continue
            if on_belt(k) or not at_rest(plant, pc, parts[k]):
                self._resting.pop(k, None)
                continue
            since = self._resting.setdefault(k, t)
            if t - since < REST_TIME - 1e-9:
                continue
            query = query or plant.get_geometry_query_input_port().Eval(pc)
            others = self._robot + [g for j in moving if j != k for g in self._parts[j]]
            if not self._near(query, self._parts[k], others, margin):
                self._joint(k).Lock(pc)
                self.locked[k] = t
                self.log.append(("lock", k, t))

    @staticmethod
    def _near(query, mine: list, others: list, margin: float) -> bool:
        for a in mine:
            for b in others:
                try:
                    if query.ComputeSignedDistancePairClosestPoints(a, b).distance < margin:
                        return True
                except RuntimeError:  # touching boxes: Drake's gradient check fails (``obstacles``)
                    return True
        return False

    def restore(self, pc) -> None:
        """In a rebuilt diagram's context: the locked parts locked again (a parameter)."""
        for k in self.locked:
            self._joint(k).Lock(pc)

    def forget(self, k: int) -> None:
        """Part k parked (its lock the truth's own now)."""
        self.locked.pop(k, None)
        self._resting.pop(k, None)
