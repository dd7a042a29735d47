"""Build everything the package ships without running it, for ``tests/unit/test_offline.py`` (started
there in a subprocess with an empty download cache): ``python offline_build.py CANARY MODEL...``.

Each bundled model file (MODEL...) is parsed into a plant of its own, with a SceneGraph (so that
every visual and collision file is resolved), by Drake's default
``PackageMap`` (which lists the remote ``drake_models``: a model that used it would be fetched into
the cache, or fail with no network) and finalized; each bundled scenario is loaded and its world
builds its diagram (``World.prepare``, no step simulated) and a default context.  Then the canary:
a remote package served from the local file CANARY (a .tar.gz holding ``canary/package.xml``) is
fetched through a ``PackageMap``, which shows where Drake's download cache is under this
environment (the test expects it there and nothing else beside it).  One line per item on stdout.
"""

from __future__ import annotations

import hashlib
import sys
from pathlib import Path

from pydrake.multibody.parsing import PackageMap, Parser
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
from pydrake.systems.framework import DiagramBuilder

from ptint_drake.simulation.scenario import bundled_scenarios, load_scenario
from ptint_drake.worlds.registry import world_of


def main(canary: str, models: list[str]) -> None:
    for path in models:
        plant, _ = AddMultibodyPlantSceneGraph(DiagramBuilder(), 0.0)  # with a SceneGraph: the
        Parser(plant).AddModels(path)  # geometry's files are resolved (a bare plant skips them)
        plant.Finalize()
        print("model", Path(path).name, flush=True)
    for name in bundled_scenarios():
        scenario = load_scenario(name)
        run = world_of(scenario).prepare(scenario, log=False)
        run.diagram.CreateDefaultContext()
        print("scenario", name, flush=True)
    params = PackageMap.RemoteParams()
    params.urls = [Path(canary).resolve().as_uri()]
    params.sha256 = hashlib.sha256(Path(canary).read_bytes()).hexdigest()
    params.strip_prefix = "canary"
    packages = PackageMap.MakeEmpty()
    packages.AddRemote("canary", params)
    print("canary", packages.GetPath("canary"), flush=True)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2:])
