"""Issue 33: the 6-joint arm (rvm1_6dof) picks and places."""

# rvm1_6dof start posture (tests/unit/test_pick_arm6.py: the wrist pitched 21.5°, clear of its singularity)
START_6DOF = [22.7, 46.5, 20.0, 0.0, 21.5, 0.0]


def test_the_six_joint_arm_picks_and_places_on_conveyor_pick_place(run):
    """rvm1_6dof, the start posture above, every controller setting left at its default (the
    damped J⁺ through the wrist singularity is the default on a 6-joint top-down task)."""
    m = run("conveyor_pick_place", "robot: {model: rvm1_6dof, end_effector: tool, initial_q_deg: "
                                   f"{START_6DOF}}}").metrics
    assert m["status"] == "ok", m["reasons"]
    p = m["picks"][0]
    assert p["placed"] and not p["collision"], p
    assert p["place_error_mm"] <= 3.0 and p["place_error_deg"] <= 3.0, p
