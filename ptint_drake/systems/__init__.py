"""The Drake systems every world and controller shares, one room per concern: the task in space
and time (``task``: the schedule of segments, the time base generator, the targets, the task
error, the arm's kinematics), estimation of an object's motion from a camera (``estimation``),
perception (``perception``: the cameras and the part poses fitted to point clouds) and the hand
(``hand``: the gripper's drive, its sensed grasp and its datasheets).  The controllers' own
kernels live beside them in ``ptint_drake.controllers``."""
