"""The bundled scenario files (``*.yaml``; ``ptint list``, ``scenario.bundled_scenarios``)."""
