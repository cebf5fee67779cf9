"""A Panda reaching around a box on a table, planned with stock RRT-Connect and BalancedRRTConnect.

Uses example-robot-data's Panda (``pip install 'ompl-balance[robots]'``): 8 joints, the
eighth being the finger opening, held at 0.02 m here. ``setup_robot`` installs the
certified motion validator: every edge of the returned path is proved collision-free
(``certify_path`` re-checks it). Prints time, path length and the collision-checking work
of each planner. Run: ``python examples/panda_table.py [--time-limit 10]``.
"""

import argparse
import sys
import time

import numpy as np
from ompl import geometric as og
from ompl import util as ou

from ompl_balance import (
    BalancedRRTConnect,
    CollisionChecker,
    Environment,
    certify_path,
    load_example_robot_data_panda,
    read_work,
    setup_robot,
    space_for,
)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--time-limit", type=float, default=10.0, help="seconds of planning per planner (default 10)")
    args = parser.parse_args()
    if not args.time_limit > 0:
        parser.error(f"--time-limit must be a positive number of seconds, got {args.time_limit}")
    ou.setLogLevel(ou.LOG_WARN)  # OMPL's Debug and Info lines would bury the results
    try:
        robot = load_example_robot_data_panda()
    except ImportError as error:  # the robots extra is not installed
        sys.exit(f"panda_table.py: {error}")
    environment = Environment()
    environment.add_box("table", half_extents=[0.6, 0.8, 0.02], position=[0.5, 0.0, -0.04])  # top 2 cm below the base
    environment.add_box("box", half_extents=[0.05, 0.2, 0.25], position=[0.5, 0.0, 0.25])
    checker = CollisionChecker(robot, environment)

    start = np.array([-0.9, 0.6, 0.0, -1.6, 0.0, 2.2, 0.8, 0.02])  # hand in front, left of the box
    goal = np.array([0.9, 0.6, 0.0, -1.6, 0.0, 2.2, 0.8, 0.02])  # mirrored, right of the box
    for side, q in (("start", start), ("goal", goal)):
        if not checker.is_valid(q):  # name what collides (or the joint limits, when nothing does)
            contacts = ", ".join(map(str, checker.collisions(q))) or "outside the joint limits"
            sys.exit(f"panda_table.py: the {side} configuration is not valid: {contacts}")

    for name, make_planner in [("RRTConnect", og.RRTConnect), ("BalancedRRTConnect", BalancedRRTConnect)]:
        ss = og.SimpleSetup(space_for(robot))
        setup_robot(ss, checker)
        si = ss.getSpaceInformation()
        s, g = si.allocState(), si.allocState()
        for i in range(robot.dof):
            s[i], g[i] = float(start[i]), float(goal[i])
        ss.setStartAndGoalStates(s, g)
        ss.setPlanner(make_planner(si))
        before = read_work(si)
        began = time.perf_counter()
        solved = ss.solve(args.time_limit)
        elapsed = time.perf_counter() - began
        work = read_work(si) - before
        length = ss.getSolutionPath().length() if solved else float("nan")
        certified = certify_path(checker, ss.getSolutionPath()).certified if solved else False
        print(
            f"{name:20s} {solved.asString() if hasattr(solved, 'asString') else solved!s:16s} {elapsed:6.2f} s  "
            f"path length {length:.2f} rad  certified {certified}  states checked {work.states_checked}  "
            f"motions checked {work.motions_checked}  distance queries {work.distance_queries}"
        )


if __name__ == "__main__":
    main()
