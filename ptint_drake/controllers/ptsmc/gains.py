"""The gains of the paper's controller and the choices it leaves open (paper section 3.1);
declared with the scenario schema (``config.controller``), named here for the systems."""

from ptint_drake.config.controller import ControllerGains

__all__ = ["ControllerGains"]
