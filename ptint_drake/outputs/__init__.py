"""A run's files on disk: written into its output folder, never left half-written (``folder``)."""
