"""Experiments and their evidence: experiment files, the run-per-process runner, OMPL logs and
database, summaries and plots (the ``ompl-balance compare``, ``bench`` and ``plot`` commands)."""
