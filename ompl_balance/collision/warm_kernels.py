"""Importing this module compiles the collision kernels (:func:`ompl_balance.collision.screening.warm_up`).

The benchmark runner's forkserver imports it with the robot layer, so that every run
process forked from it starts with the kernels ready instead of loading them (about
half a second per run).
"""

from .screening import warm_up

warm_up()
