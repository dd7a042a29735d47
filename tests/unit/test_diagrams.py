"""diagrams/ holds the current exports; `ptint diagram` writes .dot and .svg with Graphviz.

The committed .dot files are compared with a fresh export by their structure, not their bytes:
the systems (name and type), the ports of this package's systems, and every connection by
system and port name.  Drake's own systems gain ports and change their Graphviz layout between
releases (Drake 1.58's MultibodyPlant has `surface_speeds` and `surface_displacements`, which
1.51's lacks), so of those only the connected ports count.
"""

import re
import shutil
from pathlib import Path

import pytest
from script_module import load_script

from ptint_drake.report.run_outputs import write_diagram

ROOT = Path(__file__).resolve().parents[2]
DIAGRAMS = ROOT / "diagrams"
export = load_script("export_diagrams")

_NODE = re.compile(r"^(s\d+) \[shape=none.*?<B>(.*?)</B><BR/>\s*name=(.*?)\n(.*?)^>\];", re.S | re.M)
_PORT = re.compile(r'<TD PORT="([uy]\d+)"[^>]*>(.*?)</TD>', re.S)
_EDGE = re.compile(r"^(s\d+):(y\d+)(?::\w+)? -> (s\d+):(u\d+)(?::\w+)?$", re.M)
_TAG = re.compile(r"<[^>]*>")


def structure(dot: str) -> dict:
    """The systems, ports and connections of a `GetGraphvizString(max_depth=1)` export."""
    nodes = {}
    for node_id, kind, name, body in _NODE.findall(dot):
        ports = {port: _TAG.sub("", label).strip() for port, label in _PORT.findall(body)}
        nodes[node_id] = (name.strip(), _TAG.sub("", kind).strip(), ports)
    assert nodes, "no systems found in the Graphviz text"
    edges, connected = set(), set()
    for src, out, dst, inp in _EDGE.findall(dot):
        a = (nodes[src][0], nodes[src][2][out])
        b = (nodes[dst][0], nodes[dst][2][inp])
        edges.add(f"{a[0]}.{a[1]} -> {b[0]}.{b[1]}")
        connected |= {(src, out), (dst, inp)}
    systems = {}
    for node_id, (name, kind, ports) in nodes.items():
        own = kind.startswith("ptint_drake.")
        keep = {p: label for p, label in ports.items() if own or (node_id, p) in connected}
        systems[name] = {"type": kind,
                         "inputs": sorted(v for p, v in keep.items() if p.startswith("u") and v),
                         "outputs": sorted(v for p, v in keep.items() if p.startswith("y") and v)}
    return {"systems": systems, "connections": sorted(edges)}


@pytest.mark.parametrize("name", ["curve_b075_tf15", "assembly"])
def test_committed_diagrams_are_current(tmp_path, name):
    if shutil.which("dot") is None:
        pytest.fail("graphviz's dot is missing: run scripts/setup.sh")
    fused, blocks = export.diagram_scenarios(name)
    for scenario, systems in ((fused, ("interceptor", "station")),
                              (blocks, ("interceptor_tbg", "interceptor_target", "interceptor_kinematics",
                                        "interceptor_surface", "interceptor_controller", "station"))):
        dot, svg = write_diagram(scenario, tmp_path)
        committed = DIAGRAMS / dot.name
        assert committed.is_file(), \
            f"{committed} is missing: run `.venv/bin/python scripts/export_diagrams.py`"
        fresh = structure(dot.read_text())
        assert structure(committed.read_text()) == fresh, (
            f"{committed} is stale: run `.venv/bin/python scripts/export_diagrams.py`")
        assert set(systems) <= set(fresh["systems"])
        assert any(c.endswith(" -> station.actuation") for c in fresh["connections"])
        assert (DIAGRAMS / svg.name).is_file()
        text = svg.read_text()
        assert text.lstrip().startswith("<?xml") and "<svg" in text
        for system in systems:  # every block appears, wired to the station
            assert system in text


def test_structure_ignores_drake_version_details():
    """Unconnected ports of Drake's systems and the layout of the table do not count."""
    def export(extra_plant_port: str) -> str:
        return (
            's1 [shape=none, border=0, label=<\n<TABLE>\n<TR><TD COLSPAN="2">\n<B>MultibodyPlant</B><BR/>\n'
            'name=plant\n</TD></TR>\n<TR>\n<TD PORT="u0" BORDER="1" >actuation</TD>\n'
            '<TD PORT="y0" BORDER="1" >state</TD>\n</TR>\n' + extra_plant_port + '</TABLE>\n>];\n'
            's2 [shape=none, border=0, label=<\n<TABLE>\n<TR><TD COLSPAN="2">\n'
            '<B>ptint_drake.controllers.ptsmc.interceptor.PrescribedTimeInterceptor</B><BR/>\nname=interceptor\n'
            '</TD></TR>\n<TR>\n<TD PORT="u0" BORDER="1" ROWSPAN="2">state</TD>\n'
            '<TD PORT="y0" BORDER="1" >tau</TD>\n</TR>\n<TR>\n<TD PORT="y1" BORDER="1" >sigma</TD>\n'
            '</TR>\n</TABLE>\n>];\ns1:y0:e -> s2:u0:w\ns2:y0:e -> s1:u0:w\n')

    old = structure(export(""))
    assert old == structure(export('<TR>\n<TD PORT="u1" BORDER="1" >surface_speeds</TD>\n</TR>\n'))
    assert old["systems"]["interceptor"]["outputs"] == ["sigma", "tau"]
    assert old["connections"] == ["interceptor.tau -> plant.actuation", "plant.state -> interceptor.state"]


def test_diagrams_of_two_scenarios_share_a_folder(tmp_path):
    """`ptint diagram A` then `ptint diagram B --out` the same folder keeps A's files (each
    scenario's pair is named after it), and a diagram written again replaces its own pair."""
    from ptint_drake.simulation.scenario import load_scenario

    if shutil.which("dot") is None:
        pytest.skip("Graphviz's dot is not installed")
    first = write_diagram(load_scenario("curve_b075_tf15"), tmp_path)
    second = write_diagram(load_scenario("assembly"), tmp_path)
    assert all(p.exists() and p.stat().st_size > 0 for p in first + second)
    (tmp_path / "curve_b075_tf15.dot").write_text("stale")
    again = write_diagram(load_scenario("curve_b075_tf15"), tmp_path)
    assert again == first and (tmp_path / "curve_b075_tf15.dot").read_text() != "stale"
    assert all(p.exists() for p in second)
    assert not list(tmp_path.glob(".ptint-stage-*"))
