"""ptint compare: every controller × plant variant, the table's structure, bad names."""

import csv
import json

import pytest
from arms import OFFSET_ARM

SEGMENT_KEYS = {"e0_norm", "e_half_norm", "e_tf_norm", "edot_tf_norm", "e_hold_max_norm", "t_arrive",
                # the orientation metrics (null for a position task: the paper's)
                "e_rot0_deg", "e_rot_half_deg", "e_rot_tf_deg", "e_rot_hold_max_deg", "edot_rot_tf_deg_s"}


@pytest.mark.slow
def test_compare_writes_the_table_and_the_paper_controller_is_ok(tmp_path, ptint_here):
    """``ptint compare`` in this process (test_plugin.py runs it as a real command)."""
    out = ptint_here("compare", "curve_b075_tf15", "--controllers", "ptsmc,pd,ct_quintic",
                "--variants", "nominal,mass_x1.5", "--workers", "2", "--out", str(tmp_path), "--quiet")
    assert out.returncode == 0, out.stderr  # misses are results: exit 0
    result = json.loads((tmp_path / "compare.json").read_text())
    assert result["scenario"] == "curve_b075_tf15"
    rows = result["rows"]
    assert [(r["controller"], r["variant"]) for r in rows] == [
        (c, v) for v in ("nominal", "mass_x1.5") for c in ("ptsmc", "pd", "ct_quintic")]
    for row in rows:
        assert {"controller", "variant", "ok", "torque_peak_max", "segments"} <= set(row)
        assert len(row["segments"]) == 1 and set(row["segments"][0]) == SEGMENT_KEYS
        assert "curve" not in row  # the figure's data stays out of the JSON
    by = {(r["controller"], r["variant"]): r for r in rows}
    for variant in ("nominal", "mass_x1.5"):
        ptsmc = by[("ptsmc", variant)]
        assert ptsmc["ok"] and ptsmc["segments"][0]["e_tf_norm"] <= 1e-3
        assert ptsmc["segments"][0]["t_arrive"] is not None
        assert ptsmc["segments"][0]["t_arrive"] > 0.75  # not early: it arrives in the second half
    # the model-based reference needs its model: exact on nominal, off with masses × 1.5
    assert by[("ct_quintic", "nominal")]["ok"]
    assert by[("ct_quintic", "mass_x1.5")]["segments"][0]["e_tf_norm"] > 1e-3
    # a PID tuned by a rule arrives when its gains say, not at tf
    assert not by[("pd", "nominal")]["ok"]
    with open(tmp_path / "compare.csv") as f:
        table = list(csv.DictReader(f))
    assert len(table) == 6
    assert {"controller", "variant", "segment", "e_tf_norm", "t_arrive", "ok"} <= set(table[0])
    md = (tmp_path / "compare.md").read_text()
    assert md.count("\n| ptsmc |") == 2 and "| verdict |" in md
    assert (tmp_path / "compare.png").stat().st_size > 20_000
    assert "6 runs" in out.stdout and "meet the criteria" in out.stdout


def test_compare_on_an_arm_the_package_has_never_seen(tmp_path, ptint_here):
    urdf = tmp_path / "offset_arm.urdf"
    urdf.write_text(OFFSET_ARM)
    scenario = tmp_path / "reach.yaml"
    scenario.write_text(f"""duration: 2.0
robot: {{model: {urdf}, end_effector: hand, initial_q_deg: [17.2, 28.6, 68.8]}}
interceptions:
  - {{start: 0.0, tf: 1.0, beta: 0.75,
     target: {{linear: {{start: [0.42, 0.10, 0.55], velocity: [0.0, 0.05, 0.0]}}}}}}
""")
    out = ptint_here("compare", str(scenario), "--variants", "nominal", "--workers", "2",
                     "--out", str(tmp_path / "out"), "--quiet")
    assert out.returncode == 0, out.stderr
    rows = json.loads((tmp_path / "out" / "compare.json").read_text())["rows"]
    assert [r["controller"] for r in rows] == ["ptsmc", "pd", "smc", "ct_quintic"]
    assert all(r["status"] in ("ok", "missed") for r in rows), [r["reasons"] for r in rows]
    assert next(r for r in rows if r["controller"] == "ptsmc")["ok"]


@pytest.mark.parametrize("args, message", [
    (("--controllers", "ptsmc,lqr"),
     "ptint: error: --controllers: unknown 'lqr' (one of ptsmc, pd, smc, ct_quintic, or 'module:Class' "
     "(a LeafSystem in your own file))"),
    (("--variants", "nominal,heavy"), "ptint: error: variant: unknown plant variant 'heavy'"),
    (("--workers", "0"), "ptint: error: --workers: must be >= 1, got 0"),
])
def test_bad_compare_input_is_one_line(tmp_path, args, message, ptint_here):
    out = ptint_here("compare", "curve_b075_tf15", *args, "--out", str(tmp_path / "out"), "--quiet")
    assert out.returncode == 2
    assert out.stderr.startswith(message) and out.stderr.count("\n") == 1, out.stderr
    assert not (tmp_path / "out").exists()


def test_table_rows_read_the_structured_reasons():
    """The table's reasons come from ``reason_codes`` (segment, code), not from parsing the
    printed strings: a row's own codes on its segment, a failure's message on every segment."""
    from ptint_drake.studies.compare import table_rows  # noqa: PLC0415
    from ptint_drake.verdict.metrics import Reason  # noqa: PLC0415

    seg = dict.fromkeys(SEGMENT_KEYS, 0.001)
    missed = {"controller": "pd", "variant": "nominal", "status": "missed", "torque_peak_max": 1.0,
              "segments": [seg, seg], "reasons": ["(printed only)"],
              "reason_codes": [Reason(1, "late").as_dict(), Reason(1, "hold").as_dict()]}
    failed = {"controller": "smc", "variant": "nominal", "status": "failed", "torque_peak_max": 1.0,
              "segments": [seg], "reasons": ["(printed only)"],
              "reason_codes": [Reason(None, "failed", "diverged at t = 1 s").as_dict()]}
    rows = table_rows({"rows": [missed, failed]})
    assert [(r["segment"], r["ok"], r["reasons"]) for r in rows] == [
        (0, True, ""), (1, False, "late, hold"), (0, False, "diverged at t = 1 s")]
