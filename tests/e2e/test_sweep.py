"""Parameter sweeps: parallel workers, any Executor (a local Dask cluster), the CLI."""

import csv
import multiprocessing
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pytest

from ptint_drake.simulation import simulate
from ptint_drake.simulation.scenario import LoadedScenario, parse_scenario, scenario_text
from ptint_drake.studies.sweep import run_sweep, sweep_point

NAME, TEXT = scenario_text("curve_b075_tf15")


def test_sweep_point_matches_a_direct_run():
    row = sweep_point(TEXT, NAME, 0.5, 1.2)
    scenario = parse_scenario(TEXT, NAME)
    scenario.interceptions[0].beta, scenario.interceptions[0].tf = 0.5, 1.2
    scenario.duration = 3.0
    seg = simulate(scenario).metrics["segments"][0]
    assert row["ok"] and not row["error"]
    assert row["e_tf"] == pytest.approx(seg["e_tf_norm"], rel=1e-9)
    assert row["hold"] == pytest.approx(seg["e_hold_max_norm"], rel=1e-9)


def test_sweep_extends_duration_and_reports_bad_points():
    row = sweep_point(TEXT, NAME, 0.75, 2.5)  # tf beyond the 3 s duration: extended to 5 s
    assert row["ok"], row
    bad = sweep_point(TEXT.replace("center: [0.24, 0.0, 0.3]", "center: [0.9, 0.0, 0.3]"), NAME, 0.5, 1.0)
    assert not bad["ok"] and "workspace" in bad["error"]


def test_run_sweep_with_a_process_pool_keeps_grid_order():
    # forkserver: an earlier test's Dask client may leave threads in this process, and Python
    # 3.12+ warns (rightly) about fork() from a multi-threaded process
    with ProcessPoolExecutor(max_workers=2, mp_context=multiprocessing.get_context("forkserver")) as pool:
        rows = run_sweep(LoadedScenario.parse(TEXT, NAME), [0.5, 0.75], [1.5], executor=pool)
    assert [(r["beta"], r["tf"]) for r in rows] == [(0.5, 1.5), (0.75, 1.5)]
    assert all(r["ok"] for r in rows)
    # β changes the run: β = 0.75 has a larger e(tf) than β = 0.5 at the same tf (see docs/results.md)
    assert rows[1]["e_tf"] > rows[0]["e_tf"]


@pytest.mark.slow
def test_run_sweep_on_a_local_dask_cluster():
    distributed = pytest.importorskip("distributed", reason="install the [cluster] extra")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        rows = run_sweep(LoadedScenario.parse(TEXT, NAME), [0.5, 0.75], [1.2, 1.9],
                         executor=client.get_executor())
    assert len(rows) == 4 and all(r["ok"] for r in rows)
    direct = sweep_point(TEXT, NAME, 0.75, 1.9)
    assert rows[3]["e_tf"] == pytest.approx(direct["e_tf"], rel=1e-9)


@pytest.mark.slow
def test_cli_sweep_writes_csv_and_heatmaps(tmp_path, ptint_here):
    """``ptint sweep`` in this process (test_runner.py runs it as a real command)."""
    done = ptint_here("sweep", "curve_b075_tf15", "--beta", "0.5,0.75", "--tf", "1.2,1.5", "--workers", "2",
                      "--out", str(tmp_path), "--quiet")
    assert done.returncode == 0, done.stderr
    with open(tmp_path / "sweep.csv") as f:
        rows = list(csv.DictReader(f))
    grid = [(float(r["beta"]), float(r["tf"])) for r in rows]
    assert grid == [(0.5, 1.2), (0.5, 1.5), (0.75, 1.2), (0.75, 1.5)]
    for r in rows:
        assert r["ok"] == "True" and float(r["e_tf"]) < 1e-3 and float(r["realtime_factor"]) > 0
        for col in ("e0", "e_half", "hold", "peak_torque", "peak_jerk"):
            assert np.isfinite(float(r[col]))
    assert (tmp_path / "sweep.png").stat().st_size > 10_000


@pytest.mark.parametrize("args, field", [(["--beta", "0.5,1.5"], "--beta"), (["--tf", "0,1"], "--tf"),
                                         (["--beta", "a,b"], "--beta"), (["--workers", "0"], "--workers")])
def test_cli_sweep_bad_arguments(args, field, tmp_path, ptint_here):
    done = ptint_here("sweep", "curve_b075_tf15", *args, "--out", str(tmp_path))
    assert done.returncode == 2 and field in done.stderr and "Traceback" not in done.stderr
