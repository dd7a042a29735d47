"""The one error type of a scenario that cannot be run."""


class ScenarioError(ValueError):
    """A scenario that cannot be run; the message is one line and names the field."""
