"""Imported by the forkserver of a sweep with MotionBenchMaker problems (see ``runner.preload_modules``).

Importing it loads the Panda and the MotionBenchMaker scenarios shipped with the package
into the caches of :mod:`ompl_balance.bench.experiment`, once, in the forkserver: every
run's process is forked from it and starts with them instead of reading them again.
"""

from .experiment import load_shipped_mbm_data

load_shipped_mbm_data()
