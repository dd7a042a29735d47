"""What a run and the paper leave on disk: a run's folder (``run_outputs``: metrics.json,
series.npz, figures and replay drawn by the run's world) and the paper's report (``paper_report``)."""
