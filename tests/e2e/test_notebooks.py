"""The tutorial notebooks (``examples/*.ipynb``) run top to bottom on this install, with Drake's
deprecation warnings as errors (``notebook_kernel``), and reproduce their committed outputs: every
number printed by a cell tagged ``table`` equals the committed one to 3 significant digits (the
runs are deterministic; the tolerance absorbs the last digit of a float printed with more).
Any error in a cell fails the test (nbclient raises ``CellExecutionError``)."""

from __future__ import annotations

import copy
import re
import time

import nbformat
import pytest
from nbclient import NotebookClient
from notebook_kernel import EXAMPLES, NOTEBOOKS, kernel_env, kernel_name

pytestmark = pytest.mark.e2e
NUMBER = re.compile(r"[-+]?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?")
SIGNIFICANT = 3


def table_numbers(nb) -> list:
    """The numbers in the text outputs of the cells tagged ``table``, cell by cell."""
    found = []
    for cell in nb.cells:
        if cell.cell_type == "code" and "table" in cell.metadata.get("tags", []):
            text = "".join(o.get("text", "") for o in cell.outputs if o.output_type == "stream")
            found.append([float(x) for x in NUMBER.findall(text)])
    return found


def same(a: float, b: float) -> bool:
    return a == b or f"{a:.{SIGNIFICANT - 1}e}" == f"{b:.{SIGNIFICANT - 1}e}"


@pytest.mark.slow
@pytest.mark.parametrize("name", NOTEBOOKS)
def test_notebook_runs_and_reproduces_its_tables(name):
    committed = nbformat.read(EXAMPLES / f"{name}.ipynb", as_version=4)
    expected = table_numbers(committed)
    assert expected and all(expected), f"{name}: no numbers in its cells tagged table"
    nb = copy.deepcopy(committed)
    t0 = time.perf_counter()
    NotebookClient(nb, timeout=240, kernel_name=kernel_name(),
                   resources={"metadata": {"path": str(EXAMPLES)}}).execute(env=kernel_env())
    print(f"{name}: {time.perf_counter() - t0:.1f} s")
    errors = [o for c in nb.cells if c.cell_type == "code" for o in c.outputs if o.output_type == "error"]
    assert not errors
    got = table_numbers(nb)
    assert [len(c) for c in got] == [len(c) for c in expected], f"{name}: the tables changed shape"
    for cell_got, cell_expected in zip(got, expected):
        wrong = [(g, e) for g, e in zip(cell_got, cell_expected) if not same(g, e)]
        assert not wrong, f"{name}: re-executed numbers differ from the committed outputs: {wrong}"
