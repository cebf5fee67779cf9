"""Imported by the forkserver of a sweep with MotionBenchMaker problems (see ``runner.preload_modules``).

Importing it reads the Panda and the MotionBenchMaker scenarios shipped with the package
into the caches of :func:`ompl_balance.worlds.mbm.problem_setup`, once, in the forkserver:
every run's process is forked from it and starts with them instead of reading them again.
"""

from ..worlds.mbm import load_shipped_data

load_shipped_data()
