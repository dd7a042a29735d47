"""The interception world: an arm and objects that move by a known law (``world``)."""
