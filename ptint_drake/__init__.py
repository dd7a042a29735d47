"""ptint_drake: prescribed-time interception of moving objects with a robot arm, as Drake systems
(Flores-Campos et al., Robotics 2024, 13(10), 145).  The documentation site (docs/) has the
tutorials, the command line, the scenario schema and the API reference."""
