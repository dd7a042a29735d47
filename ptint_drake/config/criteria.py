"""A scenario's pass criteria (``criteria``): the numbers the verdict (``metrics.verdict``)
compares against.  (No postponed annotations: Drake's ``yaml_load_typed`` reads the types.)"""

from dataclasses import dataclass


@dataclass
class Criteria:
    """Pass criteria of a scenario (defaults: the paper's property as this project states it)."""

    e_tf: float = 1.0e-3  # m: |e(start + tf)| at most this ("late" otherwise)
    hold: float = 3.0e-3  # m: |e| while holding at most this ("hold" otherwise)
    half_fraction: float = 0.25  # |e(tf/2)| at least this × |e0| ("early" otherwise)
    min_e0: float = 1.0e-2  # m: the early check applies only when |e0| is at least this
    # tasks with orientation (controller.task pose | top_down), issue 19:
    e_rot_tf_deg: float = 2.0  # deg: the angle at start + tf at most this ("orientation" otherwise)
    rot_hold_deg: float = 5.0  # deg: the angle while holding at most this ("orientation" otherwise)
    min_e_rot0_deg: float = 5.0  # deg: the early check of the angle applies only from this
    # pick and place (issue 20): a part is placed when it rests within both of its slot
    place_mm: float = 3.0  # mm: the part's centre from its place pose at the end
    place_deg: float = 3.0  # deg: the part's orientation from its slot's at the end


