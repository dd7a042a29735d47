"""The hand: the parallel gripper's drive and its sensed grasp (``gripper``), and the bundled
grippers' datasheet limits and the arms' rated payloads (``datasheets``)."""
