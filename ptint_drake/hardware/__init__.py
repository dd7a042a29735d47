"""The hardware path (issue 35): the simulated world as "hardware" and the controller alone, two
processes talking Drake's LCM messages, with a safe stop on every fault.

- ``link``: the LCM side both processes share (URL and channels, the ``lcmt_iiwa_*`` messages of
  the arm's joint count, the checks a command passes, the timing records).
- ``session``: ``HardwareSession``, the hardware side's exchange: publishes the status, takes and
  checks each command (lockstep or real time), records the timing, names a fault.
- ``command_link``: ``CommandLink``, the hardware side's controller slot: a discrete system at the
  control period that applies the commands the session took, and holds the arm on a fault.
- ``sim_hardware``: ``ptint hardware``: the scenario's world run by the one runner with
  ``CommandLink`` in the controller slot; metrics.json (the verdict) plus the link's block.
- ``drive``: ``ptint drive``: targets and controller alone, answering each status with a command.

docs/hardware.md has the messages, channels, units and the checks before a real robot.
"""
