"""The world seam: what every world (the interception world, the pick world, …) implements, and
what a run hands back.

A *world* is one kind of scenario: which physical things are simulated, what the controller aims
at, how a run is measured and judged, and how it is drawn.  ``World`` is the protocol;
``worlds.registry`` lists the worlds and picks the one a scenario belongs to; ``worlds.runner``
owns the ``Simulator`` and its ``AdvanceTo`` loop for all of them.  A world builds a
``WorldRun`` for one scenario — the diagram and its handles — and the runner drives it:

1. ``pre_run_warnings()`` (checks before simulating; a ``ScenarioError`` stops the run);
2. ``simulator_config``, ``initialize(context)`` and ``monitor(progress)`` (the watchdog);
3. ``stops()``: the exact times ``AdvanceTo`` lands on; ``at_stop(context, t)`` after each; then
   ``replan(context, t)``: True when the world planned anew there (its ``diagram`` is new: the
   runner makes a new simulator and ``resume(new_context, old_context)`` carries the state), and
   ``stops()`` is read again;
4. ``finish(context, integrator)`` → (metrics, series, warnings after the run);
5. ``reasons(metrics, criteria)``: why it missed (the verdict), and ``sim_info`` extras.

Adding a world = one package under ``worlds/`` with a ``World`` subclass, plus one line in
``worlds.registry.WORLDS`` (docs/design.md).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Optional

from ptint_drake.config.schema import Scenario
from ptint_drake.metrics import Reason
from ptint_drake.systems.schedule import Schedule

Progress = Optional[Callable[[float, float, int], None]]


@dataclass
class RunResult:
    """A finished run: its scenario, metrics (metrics.json's content) and logged series."""

    scenario: Scenario
    metrics: dict
    series: dict = field(repr=False)

    @property
    def failed(self) -> bool:
        return self.metrics.get("status") == "failed"

    @property
    def ok(self) -> bool:
        return self.metrics.get("status") == "ok"


class WorldRun:
    """One scenario's diagram in one world, driven by ``worlds.runner.simulate`` (the module
    docstring gives the order of the calls).  Subclasses set ``diagram``, ``controller`` (the
    ``controllers.ControllerHandles``) and ``simulator_config``."""

    diagram: object
    controller: object
    simulator_config: object
    plant_time_step: float = 0.0
    # call ``AdvanceTo`` at a stop the context has reached already (t = 0): a discrete plant then
    # takes its update at that time before the stop is measured, as the pick world always did
    advance_at_reached_stops: bool = False

    def pre_run_warnings(self) -> list[str]:
        """Checks before the run: raise ``ScenarioError``, or return warnings."""
        return []

    def initialize(self, context) -> None:
        """Set what the diagram's defaults do not hold into the root ``context``."""

    def monitor(self, progress: Progress):
        """A ``Simulator`` monitor (the divergence watchdog), or None."""
        return None

    def watchdog_failure(self) -> Optional[dict]:
        """The monitor's failure ({time, message}) if it stopped the run."""
        return None

    def stops(self) -> list[float]:
        raise NotImplementedError

    def at_stop(self, context, t: float) -> None:
        """Record what is measured at the exact stop ``t``."""

    def replan(self, context, t: float) -> bool:
        """After ``at_stop``: True if the world replaced its ``diagram`` with a new plan from here."""
        return False

    def resume(self, new_context, old_context) -> None:
        """Set the new diagram's ``new_context`` from the replaced one's (after ``replan``)."""
        raise NotImplementedError

    def finish(self, context, integrator) -> tuple[dict, dict, list[str]]:
        """(metrics, series, warnings known after the run)."""
        raise NotImplementedError

    def sim_info(self, integrator) -> dict:
        """This world's own entries of metrics.json's ``sim`` block."""
        return {}


class World:
    """A kind of scenario (module docstring).  ``block``: the scenario field that holds this
    world's settings (None: the world of scenarios that have no other world's block)."""

    name: str = ""
    block: Optional[str] = None
    summary: str = ""

    def validate(self, scenario: Scenario) -> None:
        """The checks of this world that need no robot model (``ScenarioError``)."""

    def schedule(self, scenario: Scenario) -> Schedule:
        """The interceptor's segments."""
        raise NotImplementedError

    def objects(self, scenario: Scenario) -> list:
        """The analytic motions of the objects the segments aim at ([] where none exist)."""
        return []

    def prepare(self, scenario: Scenario, log: bool = True) -> WorldRun:
        """The scenario's diagram and handles (``log``: with the per-step loggers)."""
        raise NotImplementedError

    def reasons(self, metrics: dict, criteria) -> list[Reason]:
        """Why a run that was not stopped missed (empty: ``ok``)."""
        raise NotImplementedError

    def figure_files(self, scenario: Scenario) -> list[str]:
        """The figure files ``ptint run`` writes (metrics.json's ``figures``)."""
        return []

    def view_tasks(self, scenario: Scenario, series: dict, metrics: dict, stage: Path, figures: bool,
                   replay: bool, svg: bool) -> list[tuple]:
        """Arguments of ``draw_view`` for the run's figures and replay (picklable: a worker
        process draws each)."""
        return []

    def draw_view(self, name: str, series: dict, metrics: dict, stage: Path, title: str, args: tuple) -> str:
        """Draw one view of ``view_tasks`` into ``stage``; returns its name."""
        raise NotImplementedError

    def simulator_config(self, scenario: Scenario):
        """The integrator settings this world runs ``scenario`` with when they are its own (None:
        the scenario's ``simulator``); ``ptint hardware`` and ``ptint drive`` keep them."""
        return None

    def controller_side(self, builder, scenario: Scenario, period: float):
        """``ptint drive``'s part of this world beyond the arm's state: systems added to
        ``builder`` that the controller aims with and their handles (``target``: its target
        view), fed from exported inputs of what the hardware side sends; None: the world's
        analytic targets suffice (``hardware.drive``)."""
        return None

    def floor_diagram(self, scenario: Scenario, kind: str):
        """``ptint bench``'s floor diagrams (``studies.benchmark.floors``), or None."""
        return None

    # Hooks of the studies and the command line: None (or {}) where the world takes the common path.

    def report(self, scenario: Scenario, metrics: dict, out) -> Optional[int]:
        """Print ``ptint run``'s lines of a finished run and return the exit code, or None."""
        return None

    def tune_refusal(self, name: str) -> Optional[str]:
        """Why ``ptint tune`` cannot search this world's scenario ``name`` (None: it can)."""
        return None

    def robust_sample(self, scenario: Scenario, name: str, seed: int, u) -> Optional[tuple]:
        """(scenario, params) of a ``robust`` sample drawn with ``u(key, size=None)``, or None."""
        return None

    def robust_row(self, seed: int, params: dict, metrics: dict) -> Optional[dict]:
        """What a ``robust`` sample keeps of its metrics, or None."""
        return None

    def robust_summary(self, rows: list) -> dict:
        """This world's entries of robust.json's summary."""
        return {}

    def sweep_point(self, row: dict, scenario: Scenario, beta: float, tf: float, simulate, validate
                    ) -> Optional[dict]:
        """A ``sweep`` grid point (β of every segment, tf), simulated, or None."""
        return None
