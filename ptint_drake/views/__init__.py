"""Views of a run: its matplotlib figures (``plots``, laid out by ``plot_grid`` and marked by
``plot_marks``, with derivatives of logged signals from ``derivatives``) and its standalone 3-D
HTML replay (``replay``, its page in ``replay_page``)."""
