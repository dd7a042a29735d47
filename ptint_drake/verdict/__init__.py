"""What a run achieved and whether it is to be believed: the metrics and the one verdict
(``metrics``), the warnings before and after a run (``run_warnings``) and the divergence
watchdog that stops a run going nowhere (``watchdog``)."""
