"""A line that runs itself (issue 44, ``config.line``): the arrival process and its pool of parts
(``arrivals``), the truth side's parking, release and belt drive (``truth``), the online
scheduler (``scheduler``: a pure function over what the controller side knows), the run's glue
(``driver``), the idle plan (``plan``) and the line's metrics (``metrics``)."""
