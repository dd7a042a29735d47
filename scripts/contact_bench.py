"""Measures Drake's discrete contact approximations on the pick world (issue 20) and prints JSON.

For Drake's default approximation and each of sap, tamsi, lagged, similar that the installed Drake
has (tamsi is gone from Drake 1.58; the PD-controlled finger and belt actuators need a SAP-family
solver, so tamsi reports its error): the hold experiment of ``ptint_drake.worlds.pick.holding`` — the
5-joint RV-M1 held still by a joint PD, a belt running at 0.1 m/s with a 30 mm box riding it, a
second box held by the closed gripper (30 N per finger) — over ``--duration`` s, with point
contact (and, with ``--hydroelastic``, Drake's hydroelastic_with_fallback as extra rows).

    PYTHONPATH=$PWD python scripts/contact_bench.py [--duration 2] [--hydroelastic]
"""

from __future__ import annotations

import argparse
import json
from importlib.metadata import version

from pydrake.multibody.plant import MultibodyPlantConfig

from ptint_drake.worlds.pick.config import (BeltConfig, GripperConfig, PartConfig, PickWorldConfig,
                                            contact_approximations)
from ptint_drake.worlds.pick.holding import measure_hold

CANDIDATES = ("sap", "tamsi", "lagged", "similar")


def bench_world(approximation: str, contact_model: str) -> PickWorldConfig:
    """The benchmark's world: one belt with a riding part, one part to hold."""
    return PickWorldConfig(
        contact_approximation=approximation, contact_model=contact_model,
        gripper=GripperConfig(initial_opening=0.031),
        belts=[BeltConfig()],
        parts=[PartConfig(name="held"), PartConfig(name="riding", offset=-0.2)])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=2.0)
    parser.add_argument("--hydroelastic", action="store_true")
    args = parser.parse_args()
    default = MultibodyPlantConfig().discrete_contact_approximation
    models = ["point"] + (["hydroelastic_with_fallback"] if args.hydroelastic else [])
    rows = []
    for model in models:
        for approximation in (default,) + tuple(c for c in CANDIDATES if c != default):
            row = {"approximation": approximation, "contact_model": model,
                   "drake_default": approximation == default}
            if approximation not in contact_approximations():
                row["error"] = "not in this Drake"
            else:
                try:
                    row.update(measure_hold(bench_world(approximation, model), args.duration))
                except Exception as exc:  # e.g. tamsi with PD-controlled actuators
                    row["error"] = " ".join(str(exc).split())[:200]
            rows.append(row)
    rows = [{k: round(v, 4) if isinstance(v, float) else v for k, v in row.items()} for row in rows]
    print("{" + f'"drake": "{version("drake")}", "duration_s": {args.duration}, "rows": [\n  '
          + ",\n  ".join(json.dumps(row) for row in rows) + "]}")


if __name__ == "__main__":
    main()
