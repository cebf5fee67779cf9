"""The rigid-body problems the package ships: their meshes are the generator's, starts and goals
are valid, and each is solved (seeded, in a fresh process) with a path that is certified and
free under a dense exact re-check with rotation sub-steps."""

import itertools
import json

import numpy as np
import pytest
from fresh_process import run_with_seed
from rigid_oracles import DenseCheck

from ompl_balance.worlds.rigid import RIGID_DIR, RIGID_PROBLEMS, ROBOTS, rigid_problem, robot_obj

#: Problems solved in the default test run; the others are marked slow.
QUICK = ("se2_slot", "se2_bugtrap", "se3_room")


def test_robot_files_are_the_generators():
    for name in ROBOTS:
        assert (RIGID_DIR / f"{name}.obj").read_text() == robot_obj(name), f"regenerate {name}.obj (write_robot_meshes)"


@pytest.mark.parametrize("name", RIGID_PROBLEMS)
def test_start_and_goal_are_valid_and_inside(name):
    problem = rigid_problem(name)
    checker = problem.checker()
    for state in (problem.start, problem.goal):
        assert checker.inside_bounds(state) and checker.is_valid(state)
    assert all(p.shape.convex for p in problem.body.parts)  # certified by GJK alone
    assert problem.time_limit and problem.time_limit > 0


def test_unknown_problem_is_refused():
    with pytest.raises(ValueError, match="neither a shipped rigid-body problem"):
        rigid_problem("se3_nowhere")


SOLVE = """
import json, sys
from ompl import base as ob, geometric as og, util as ou
ou.RNG.setSeed(int(sys.argv[1]))
ou.setLogLevel(ou.LOG_ERROR)
from ompl_balance.validity import certify_path, rigid_state_values
from ompl_balance.worlds.rigid import rigid_problem
problem = rigid_problem({name!r})
checker = problem.checker()
ss = problem.simple_setup(checker=checker)
ss.setPlanner(og.RRTConnect(ss.getSpaceInformation()))
budget = iter(range({iterations}))  # termination by iterations: the seeded run is the same on any machine
ss.solve(ob.PlannerTerminationCondition(lambda: next(budget, None) is None))
path = ss.getSolutionPath() if ss.haveExactSolutionPath() else None
states = [] if path is None else [rigid_state_values(path.getState(i), problem.body.state_size).tolist()
                                  for i in range(path.getStateCount())]
print(json.dumps({{"solved": path is not None, "states": states,
                  "certified": path is not None and certify_path(checker, path).certified}}))
"""


@pytest.mark.parametrize("name", [n if n in QUICK else pytest.param(n, marks=pytest.mark.slow) for n in RIGID_PROBLEMS])
def test_every_shipped_problem_is_solved_with_a_certified_path(name):
    result = json.loads(run_with_seed(SOLVE.format(name=name, iterations=400_000), seed=7).splitlines()[-1])
    assert result["solved"] and result["certified"]
    problem = rigid_problem(name)
    states = np.array(result["states"])
    np.testing.assert_allclose(states[0], problem.start, atol=1e-9)
    dense = DenseCheck(problem.body, problem.environment, step=2e-3)
    assert all(dense.first_collision(a, b) is None for a, b in itertools.pairwise(states))
