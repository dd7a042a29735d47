"""How the tutorial notebooks (``examples/*.ipynb``) are executed, by ``scripts/make_notebooks.py``
and by ``tests/e2e/test_notebooks.py`` alike: the ``python3`` kernel of ipykernel (the running
interpreter: jupyter_client resolves that name to ``sys.executable``), the folder this process
imports ``ptint_drake`` from first on the kernel's ``PYTHONPATH`` (the source tree for an editable
install, else the environment's site-packages: the kernel runs the package this process runs, and
finds numba's kernels where setup.sh compiled them), and Drake's deprecations as errors through its
environment switches (``DRAKE_DEPRECATION_RUNTIME_SEVERITY`` on Drake >= 1.52,
``_DRAKE_DEPRECATION_IS_ERROR`` on 1.51) besides the notebooks' own first cell
(``warnings.simplefilter("error", DrakeDeprecationWarning)``).
"""

from __future__ import annotations

import os
from pathlib import Path

import ptint_drake

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"
NOTEBOOKS = ("your_diagram", "camera", "which_controller", "pose", "pick_and_place", "hardware")


def kernel_name() -> str:
    """The kernel spec: ipykernel's native one, i.e. this interpreter."""
    return "python3"


def kernel_env() -> dict:
    """The kernel's environment: this one, this process's ``ptint_drake`` importable first,
    deprecations as errors, matplotlib drawing without a display."""
    env = dict(os.environ)
    here = str(Path(ptint_drake.__file__).resolve().parents[1])
    env["PYTHONPATH"] = os.pathsep.join(p for p in (here, env.get("PYTHONPATH", "")) if p)
    env.update(DRAKE_DEPRECATION_RUNTIME_SEVERITY="error", _DRAKE_DEPRECATION_IS_ERROR="1",
               PYDEVD_DISABLE_FILE_VALIDATION="1")
    env.pop("MPLBACKEND", None)
    return env
