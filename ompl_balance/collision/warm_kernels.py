"""Importing this module compiles the collision kernels: the checker's
(:func:`ompl_balance.collision.screening.warm_up`) and the certified motions'
(:func:`ompl_balance.collision.certified.warm_up`).

The benchmark runner's forkserver imports it with the robot layer, so that every run
process forked from it starts with the kernels ready instead of loading them (about
half a second per run).
"""

from . import certified, screening

screening.warm_up()
certified.warm_up()
