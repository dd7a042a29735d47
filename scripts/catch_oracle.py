"""The catch world's reachability oracle (issue 46), frozen: is a throw catchable at all?

It fixes the thrower's seeded distribution and decides, from the ball's *true* flight (quadratic air
drag, integrated by scipy), whether some catch time t_c exists at which the KUKA iiwa 14 with the
full-size Schunk WSG 50-110 could hold its fingertip centre on the ball's centre, the hand's
approach axis within ``APPROACH_CONE`` of the ball's incoming direction, after ``SENSING`` s of
sensing plus the arm's minimum prescribed time:

- the catch posture and every posture along the planned profile come from Drake's
  ``InverseKinematics`` (the model's joint position limits), the orientation turned on the same
  time base as the position (x = x_c + ξ(τ) (x_0 − x_c), the TBG's ξ with β = ``BETA``);
- the minimum tf is the feasibility model of ``verdict.run_warnings.joint_demand`` (the joint speeds
  |J⁺ẋ| against the velocity limits, the inverse dynamics' torques of the arm with its gripper
  against the effort limits); speeds scale as 1/tf and the torques, gravity aside, as 1/tf², so one
  evaluation at tf = 1 s gives the smallest tf that keeps every sample within both limits;
- a throw is catchable when some t_c on a ``GRID`` s grid, with the ball above ``FLOOR_Z``, has
  t_c − ``SENSING`` ≥ tf_min(t_c).  The earliest such t_c is reported.

The thrower (``throw``): a launch point 1.2–2.0 m from the arm's base (horizontally, within ±30° of
the arm's +x, 0.7–1.3 m high), a flight time of 0.6–0.9 s to an aim point uniformly spread in a ball
of radius 0.15 m around the hand's start point; the launch velocity is shot (``_shoot``) so that the
*dragged* ball passes the aim point at the flight time.  A throw is a function of its seed alone.

This script is the yardstick of the catch rate: the world's thrower must draw the same throws (a
test compares them), and it must not change after its first commit.

Usage: ``python scripts/catch_oracle.py --seeds 0-199 [--out oracle.json]`` (JSON: per seed the
throw, ``catchable``, the earliest catch time and its tf_min, or the reason it is not).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from dataclasses import dataclass

import numpy as np
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.multibody.inverse_kinematics import InverseKinematics
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant
from pydrake.solvers import Solve
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

from ptint_drake.robot.plant import effort_limits, resolve_model
from ptint_drake.systems.task.tbg import tbg_profile
from ptint_drake.verdict.run_warnings import Profile, joint_demand

# --- the ball (models/README.md, "The catch ball") and the air -------------------------------------
BALL_DIAMETER = 0.065  # m
BALL_MASS = 0.040  # kg
DRAG_CD = 0.47  # a smooth sphere's drag coefficient at Re ~ 1e4-1e5 (subcritical)
AIR_DENSITY = 1.204  # kg/m^3, dry air at 20 degC and 101.325 kPa
GRAVITY = np.array([0.0, 0.0, -9.81])

# --- the thrower's distribution (frozen) -----------------------------------------------------------
LAUNCH_DISTANCE = (1.2, 2.0)  # m from the arm's base, horizontally
LAUNCH_AZIMUTH_DEG = (-30.0, 30.0)  # about the base's +x axis
LAUNCH_HEIGHT = (0.7, 1.3)  # m
FLIGHT_TIME = (0.6, 0.9)  # s, launch to the aim point
AIM_RADIUS = 0.15  # m: aim points uniform in a ball of this radius about the hand's start point

# --- the arm, its hand and the decision -----------------------------------------------------------
ARM, HAND, TIP = "iiwa14", "schunk_wsg_50_110_full", "schunk_wsg_50_110_full_tip"
START_Q_DEG = (0.0, 30.0, 0.0, -95.0, 0.0, -95.0, 90.0)  # the hand up and toward +x (60 deg), jaws along y
SENSING = 0.15  # s of flight seen before the arm may move
BETA = 0.75  # the TBG's beta of the catch segment
ROT_SCALE = 0.1  # m/rad, the controller's weighing of the rotation (pick_iiwa14's)
PINV_DAMPING = 0.01  # m/rad, the controller's damped pseudoinverse
APPROACH_CONE_DEG = 25.0  # the approach axis within this of the ball's incoming direction
FLOOR_Z = 0.2  # m: no catch below this height
GRID = 0.02  # s between the candidate catch times
SAMPLES = 11  # samples of a catch profile (tau / tf in [0.05, 1])


def drag_per_mass() -> float:
    """k / m of the drag acceleration −(k/m)|v|v (1/m), k = ½ ρ C_d A."""
    return 0.5 * AIR_DENSITY * DRAG_CD * np.pi * (BALL_DIAMETER / 2) ** 2 / BALL_MASS


def flight(p0, v0, t_end: float):
    """The dragged ball's dense solution from ``p0``, ``v0`` at t = 0 to ``t_end`` (state [p; v])."""
    c = drag_per_mass()

    def rhs(_t, y):
        v = y[3:]
        return np.concatenate([v, GRAVITY - c * np.linalg.norm(v) * v])

    return solve_ivp(rhs, (0.0, t_end), np.concatenate([p0, v0]), rtol=1e-10, atol=1e-12,
                     dense_output=True).sol


def _shoot(p0, aim, T: float) -> np.ndarray:
    """The launch velocity whose dragged flight passes ``aim`` at ``T`` (from the drag-free one)."""
    v0 = (aim - p0 - 0.5 * GRAVITY * T ** 2) / T
    for _ in range(8):
        v0 = v0 + (aim - flight(p0, v0, T)(T)[:3]) / T
    return v0


@dataclass(frozen=True)
class Throw:
    """One throw: launch point and velocity (world, m, m/s), aim point, flight time to it (s)."""

    seed: int
    launch: tuple
    velocity: tuple
    aim: tuple
    flight_time: float


def throw(seed: int, hand_start: np.ndarray) -> Throw:
    """Throw number ``seed`` of the frozen distribution (module docstring), aimed about ``hand_start``."""
    rng = np.random.default_rng([46, int(seed)])
    d = rng.uniform(*LAUNCH_DISTANCE)
    az = np.radians(rng.uniform(*LAUNCH_AZIMUTH_DEG))
    p0 = np.array([d * np.cos(az), d * np.sin(az), rng.uniform(*LAUNCH_HEIGHT)])
    T = rng.uniform(*FLIGHT_TIME)
    u = rng.normal(size=3)
    aim = hand_start + AIM_RADIUS * np.cbrt(rng.uniform()) * u / np.linalg.norm(u)
    v0 = _shoot(p0, aim, T)
    return Throw(int(seed), tuple(p0), tuple(v0), tuple(aim), float(T))


def catch_plant() -> MultibodyPlant:
    """The iiwa 14 with the WSG 50-110 welded at its tip frame (continuous, finalized)."""
    plant = MultibodyPlant(0.0)
    (arm,) = Parser(plant, "arm").AddModels(str(resolve_model(ARM)))
    (hand,) = Parser(plant, "gripper").AddModels(str(resolve_model(ARM).parent / f"{HAND}.sdf"))
    plant.WeldFrames(plant.GetFrameByName(TIP, arm), plant.GetFrameByName("fingertip_center", hand),
                     RigidTransform())
    plant.Finalize()
    return plant


class Oracle:
    """The decision for one plant (module docstring)."""

    def __init__(self):
        self.plant = plant = catch_plant()
        self.frame = plant.GetFrameByName(TIP)
        self.q0 = np.zeros(plant.num_positions())
        self.q0[:7] = np.radians(START_Q_DEG)
        self.context = plant.CreateDefaultContext()
        plant.SetPositions(self.context, self.q0)
        self.X0 = self.frame.CalcPoseInWorld(self.context)
        self.speed_limits = plant.GetVelocityUpperLimits()[:7]
        self.efforts = effort_limits(plant)[:7]

    def ik(self, x, guess, R=None, approach=None):
        """Joint positions (within limits, fingers at 0) nearest ``guess`` with the tip at ``x`` and
        the orientation ``R``, or the approach axis within ``APPROACH_CONE_DEG`` of ``approach``;
        None if none was found."""
        ik = InverseKinematics(self.plant, with_joint_limits=True)
        ik.AddPositionConstraint(self.frame, np.zeros(3), self.plant.world_frame(), x - 1e-4, x + 1e-4)
        if approach is not None:
            ik.AddAngleBetweenVectorsConstraint(self.frame, [0.0, 0.0, 1.0], self.plant.world_frame(),
                                                approach, 0.0, np.radians(APPROACH_CONE_DEG))
        if R is not None:
            ik.AddOrientationConstraint(self.plant.world_frame(), RotationMatrix(R), self.frame,
                                        RotationMatrix(), 1e-3)
        ik.prog().AddBoundingBoxConstraint(0.0, 0.0, ik.q()[7:])
        ik.prog().AddQuadraticErrorCost(np.eye(7), guess[:7], ik.q()[:7])
        ik.prog().SetInitialGuess(ik.q(), guess)
        result = Solve(ik.prog())
        return result.GetSolution(ik.q()) if result.is_success() else None

    def tf_min(self, x_c, R_c):
        """The smallest tf of the profile from the start pose to (``x_c``, ``R_c``), or None where a
        posture along it is out of reach."""
        fractions = np.linspace(0.05, 1.0, SAMPLES)
        xi, xi_d, xi_dd = tbg_profile(fractions, 1.0, BETA)[0:3]
        e0 = self.X0.translation() - x_c
        turn = Rotation.from_matrix(R_c.T @ self.X0.rotation().matrix()).as_rotvec()  # R0 = Rc exp(turn)
        w = R_c @ turn
        postures, q = [], self.q0
        for k in range(SAMPLES):
            R = R_c @ Rotation.from_rotvec(xi[k] * turn).as_matrix()
            q = self.ik(x_c + xi[k] * e0, q, R=R)
            if q is None:
                return None
            postures.append(q)
        q_all = np.array(postures)
        vel = np.hstack([np.outer(xi_d, w), np.outer(xi_d, e0)])
        acc = np.hstack([np.outer(xi_dd, w), np.outer(xi_dd, e0)])
        moving = joint_demand(self.plant, self.frame, Profile(fractions, q_all, vel, acc),
                              rot_scale=ROT_SCALE, damping=PINV_DAMPING)
        still = joint_demand(self.plant, self.frame, Profile(fractions, q_all, 0 * vel, 0 * acc),
                             rot_scale=ROT_SCALE, damping=PINV_DAMPING)[1]
        speed = float(np.max(moving[0][:, :7] / self.speed_limits))
        return max(speed, _torque_tf(moving[1][:, :7], still[:, :7], self.efforts))

    def decide(self, th: Throw) -> dict:
        """The oracle's answer for throw ``th`` (module docstring)."""
        t_end = th.flight_time + 0.4
        sol = flight(np.array(th.launch), np.array(th.velocity), t_end)
        seen = {"reachable_points": 0}
        for t_c in np.arange(SENSING + GRID, t_end + 1e-9, GRID):
            p, v = sol(t_c)[:3], sol(t_c)[3:]
            if p[2] < FLOOR_Z:
                break
            q_c = self.ik(p, self.q0, approach=-v / np.linalg.norm(v))
            if q_c is None:
                continue
            seen["reachable_points"] += 1
            self.plant.SetPositions(self.context, q_c)
            R_c = self.frame.CalcPoseInWorld(self.context).rotation().matrix()
            tf = self.tf_min(p, R_c)
            if tf is not None and t_c - SENSING >= tf:
                return {"catchable": True, "t_catch": round(float(t_c), 4), "tf_min": round(tf, 4),
                        "catch_point": np.round(p, 4).tolist(), **seen}
        reason = "no catch point in reach" if not seen["reachable_points"] else "too fast for the arm"
        return {"catchable": False, "reason": reason, **seen}


def _torque_tf(moving: np.ndarray, still: np.ndarray, limits: np.ndarray) -> float:
    """The smallest tf with |a/tf² + g| ≤ L at every sample and joint (a = moving − still at tf =
    1, with their signs lost by |·|: the bound uses |a| against L − |g|); inf when gravity alone
    exceeds a limit."""
    a, g = np.abs(moving - still), np.abs(still)
    room = limits - g
    if np.any(room <= 0):
        return float("inf")
    return float(np.sqrt(np.max(a / room)))


def _seeds(text: str) -> list[int]:
    if "-" in text:
        lo, hi = text.split("-")
        return list(range(int(lo), int(hi) + 1))
    return [int(s) for s in text.split(",")]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", default="0-199", help="a range a-b or a list a,b,c")
    parser.add_argument("--out", help="write the JSON here (default: stdout)")
    args = parser.parse_args(argv)
    try:
        seeds = _seeds(args.seeds)
    except ValueError:
        print(f"--seeds: expected a-b or a,b,c, got {args.seeds!r}", file=sys.stderr)
        return 2
    oracle = Oracle()
    t0 = time.perf_counter()
    rows = []
    for s in seeds:
        th = throw(s, oracle.X0.translation())
        rows.append({"seed": s, "launch": np.round(th.launch, 4).tolist(),
                     "velocity": np.round(th.velocity, 4).tolist(), "aim": np.round(th.aim, 4).tolist(),
                     "flight_time": round(th.flight_time, 4), **oracle.decide(th)})
    n = sum(r["catchable"] for r in rows)
    out = {"throws": len(rows), "catchable": n, "reachable_rate": n / max(len(rows), 1),
           "wall_s": round(time.perf_counter() - t0, 1), "rows": rows}
    text = json.dumps(out, indent=1)
    if args.out:
        with open(args.out, "w") as f:
            f.write(text + "\n")
    else:
        print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
