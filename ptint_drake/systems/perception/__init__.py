"""The sensors and what is fitted to them: the formula camera of one object's position
(``camera``: sampled, noisy, late, sometimes missing), the rendered RGB-D camera and its depth
noise (``rgbd_camera``, ``depth_noise``), the scene it renders (``scene_geometry``), the part
poses fitted to its point clouds (``part_fit``, ``part_pose_estimator``) and a run's frames as
images (``frame_images``)."""
