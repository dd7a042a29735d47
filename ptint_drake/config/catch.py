"""The catch world's settings (scenario key ``catch``, issue 46): which throw of the frozen
thrower (``scripts/catch_oracle.py``), the hand, and the planner's times."""


from dataclasses import dataclass, field

from ptint_drake.config.pick import GripperConfig


def _wsg() -> GripperConfig:
    # the full-size WSG 50-110 (systems/hand/datasheets.py): 420 mm/s jaws; pre-shaped to the
    # ball's 65 mm + 2 x 8 mm
    return GripperConfig(model="schunk_wsg_50_110_full", max_force=40.0, speed=0.42, kp=20000.0, kd=40.0,
                         initial_opening=0.081)


@dataclass
class CatchConfig:
    """A catch: ``throw`` (the thrower's seed), the ``gripper``, ``predictor`` (the ball's
    estimator: ``fit``, the dragged flight fitted to the samples, or ``auto``, the scenario's
    camera estimator), ``sensing`` (s of flight seen
    before the plan), ``replan_every`` (s between the revisions of the catch time),
    ``commit`` (s before the catch time after which the plan stays), ``beta`` (the TBG's β),
    ``held_for`` (s after the catch at which the ball must still be held), ``time_step`` (s, the
    station's plant step: 1 ms; halved to check the impact's convergence); the moving target
    (``worlds.catch.target``): ``match`` (the fraction of the ball's velocity the hand has at the
    catch), ``match_time`` (s, how long before the catch the matching sets in), ``freeze`` (s
    before the catch from which the estimate is held); ``final`` (s: the catch segment split in two,
    the second this long, so that a new segment starts from the state near the catch; 0: one);
    ``close_lag`` (s after the catch at which the closing jaws reach the ball's diameter: the palm
    takes the impact first, ``worlds.catch.target``)."""

    throw: int = 0
    gripper: GripperConfig = field(default_factory=_wsg)
    predictor: str = "fit"
    sensing: float = 0.15
    replan_every: float = 0.02
    commit: float = 0.15
    beta: float = 0.5
    held_for: float = 0.5
    time_step: float = 0.001
    match: float = 0.3
    match_time: float = 0.2
    freeze: float = 0.06
    final: float = 0.0
    close_lag: float = 0.004
