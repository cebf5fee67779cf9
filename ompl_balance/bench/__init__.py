"""Experiments and their evidence: experiment files, runs each in its own process, OMPL logs and
database, summaries and plots (the ``ompl-balance compare``, ``bench`` and ``plot`` commands)."""
