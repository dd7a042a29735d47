"""The worlds a scenario runs in (``base``: the protocol; ``registry``: which world a scenario
belongs to; ``runner``: the one simulation loop; ``interception`` and ``pick``: the two worlds)."""
