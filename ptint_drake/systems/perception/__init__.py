"""Perception from a rendered RGB-D camera (issue 34): the camera and its depth noise
(``rgbd_camera``, ``depth_noise``), the scene it renders (``scene_geometry``), the part poses
fitted to its point clouds (``part_fit``, ``part_pose_estimator``)."""
