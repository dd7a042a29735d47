"""The bundled robot and gripper models (URDF/SDFormat) and their documented assumptions
(``README.md`` beside them); ``ptint_drake.robot.rvm1.bundled_models`` lists the arms."""
