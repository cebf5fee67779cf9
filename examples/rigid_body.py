"""A rigid body out of a cage (or any OMPL.app problem file), planned with stock RRT-Connect and
BalancedRRTConnect, every motion proven collision-free.

``rigid_problem("se3_cage")``: an L-shaped robot starts upright inside a closed cage with one
narrow window. Give an OMPL.app ``.cfg`` file instead (``python examples/rigid_body.py
path/to/resources/3D/cubicles.cfg``) to plan on it. Prints, per planner, whether it solved, the
time, the work the checker did and whether ``certify_path`` proves the returned path free.
Run: ``python examples/rigid_body.py [problem.cfg]``.
"""

import argparse
import time

from ompl import geometric as og
from ompl import util as ou

from ompl_balance import BalancedRRTConnect, certify_path, load_omplapp, read_work, rigid_problem


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("cfg", nargs="?", help="an OMPL.app problem file (default: the shipped se3_cage)")
    args = parser.parse_args()
    ou.setLogLevel(ou.LOG_WARN)
    problem = load_omplapp(args.cfg) if args.cfg else rigid_problem("se3_cage")
    print(
        f"{problem.name}: {problem.space}, {len(problem.body.parts)} body parts, "
        f"{len(problem.environment.obstacles)} obstacles"
    )
    for planner in (og.RRTConnect, BalancedRRTConnect):
        checker = problem.checker()
        ss = problem.simple_setup(checker=checker)  # certified motions
        made = planner(ss.getSpaceInformation())
        ss.setPlanner(made)
        ss.setup()
        began = time.perf_counter()
        ss.solve(problem.time_limit or 10.0)
        elapsed = time.perf_counter() - began
        work = read_work(ss.getSpaceInformation())
        solved = ss.haveExactSolutionPath()
        certified = solved and certify_path(checker, ss.getSolutionPath()).certified
        stats = getattr(made, "stats", None)  # the package's planners: which engine solved
        engine = "" if stats is None else f" ({stats.engine} engine)"
        print(
            f"{planner.__name__:>20}: solved {solved}, {elapsed:.2f} s{engine}, {work.states_checked} states, "
            f"{work.motions_checked} motions checked; path certified: {certified}"
        )


if __name__ == "__main__":
    main()
