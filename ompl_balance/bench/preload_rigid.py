"""Imported by the forkserver of a sweep with rigid-body problems (see ``problems.PROBLEM_KINDS``).

It compiles the rigid-body kernels and loads the compiled engine for them with certified motions,
the default (with a notice the first time after installing, when numba compiles rather than loads
from its cache), once: every run's process is forked from the forkserver and starts with them.
"""

from .compile_notice import compile_notice

with compile_notice("the rigid-body collision kernels"):
    from ..collision.rigid.checker import warm_up

    warm_up()


def _load_engine() -> None:
    """The compiled engine for rigid bodies in SE(2) and SE(3) with certified motions (a run with
    discrete motions loads its engine itself, untimed)."""
    from ..planners import BalancedRRTConnect
    from ..worlds.rigid import rigid_problem

    for name in ("se2_slot", "se3_slot"):
        ss = rigid_problem(name).simple_setup(motion="certified")
        planner = BalancedRRTConnect(ss.getSpaceInformation())
        ss.setPlanner(planner)
        ss.setup()
        planner.wait_for_engine()


_load_engine()
