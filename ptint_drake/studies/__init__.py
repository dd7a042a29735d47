"""Studies that run many simulations: sweeps, Monte Carlo, controller comparison, benchmark.

They sit side by side and share only the runner (``studies.runner``); none imports another."""
