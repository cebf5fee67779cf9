"""Imported by the forkserver of a sweep with robot problems (see ``problems.PROBLEM_KINDS``).

It compiles the robot layer's kernels (with a notice the first time after installing, when
numba compiles rather than loads them from its cache) and reads the Panda and the
MotionBenchMaker scenarios shipped with the package into the caches of
:func:`ompl_balance.worlds.mbm.problem_setup`, once: every run's process is forked from the
forkserver and starts with them instead of compiling and reading them again.
"""

from .compile_notice import compile_notice

with compile_notice("the robot layer's collision kernels"):
    from ..collision import warm_kernels  # noqa: F401  (compiles them when imported)
    from ..worlds.mbm import load_shipped_data

load_shipped_data()


def _load_engine() -> None:
    """The compiled engine for robots with certified motions (the default; a run with discrete
    motions loads its engine itself, untimed)."""
    from ..collision.checker import CollisionChecker
    from ..collision.robots import load_panda_vamp
    from ..planners import BalancedRRTConnect
    from ..worlds.mbm import load_mbm

    robot = load_panda_vamp()
    problem = load_mbm("table_pick", robot.joint_names)[0]
    ss = problem.simple_setup(robot, CollisionChecker(robot, problem.environment), motion="certified")
    planner = BalancedRRTConnect(ss.getSpaceInformation())
    ss.setPlanner(planner)
    ss.setup()
    planner.wait_for_engine()


_load_engine()
