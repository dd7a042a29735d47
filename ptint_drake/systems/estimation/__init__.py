"""Estimating an object's motion from camera samples: what every estimator shares
(``sampled_estimator``), the Kalman filters and the choice among them (``kalman``), the IMM of
``estimator: auto`` (``imm``, compiled in ``imm_kernels``), the orientation tracker
(``rotation_estimator``) and the active object's predicted target (``target_prediction``)."""
