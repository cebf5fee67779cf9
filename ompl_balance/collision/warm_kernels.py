"""Importing this module compiles the collision kernels: the checker's screening
(:func:`ompl_balance.collision.screening.warm_up`) and the compiled views of the checker and
its motion validators (:func:`ompl_balance.collision.kernels.warm_up`).

The benchmark runner's forkserver imports it with the robot layer, so that every run
process forked from it starts with the kernels ready instead of loading them (about
half a second per run).
"""

from . import kernels, screening

screening.warm_up()
kernels.warm_up()
