"""The classroom RRT-Connect variants: each policy on a hand-made situation, the presets, parameters."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from ompl import base as ob
from ompl import geometric as og
from ompl import tools as ot
from ompl import util as ou
from pathcheck import assert_valid_solution

from ompl_balance.core.trees import ArrayTree
from ompl_balance.engine.events import Grow, LoopRecord
from ompl_balance.planners import PRESETS, BalancedRRTConnect, GaussianPassageRRTConnect
from ompl_balance.policies import (
    NEAREST_POLICIES,
    SAMPLE_ATTEMPTS,
    SAMPLE_POLICIES,
    SWAP_POLICIES,
    NearestChoice,
    NodeFailures,
    SampleContext,
    SamplerCounts,
    SwapCause,
    SwapState,
    TreeChoice,
    balance_choice,
    choose_tree,
    exhaustion_scale,
    nearest_by_exhaustion,
    nearest_not_exhausted,
    node_quality,
    target_choice,
)
from ompl_balance.samplers import GaussianValidStateSampler
from ompl_balance.worlds.boxes import TWIN_POCKETS, circle_setup, get_problem

ALTERNATE, BALANCE, STEPS, COLLISION = SwapCause

ou.setLogLevel(ou.LOG_WARN)


# -- pure rules ---------------------------------------------------------------------------


def tree_rule(swap_policy, balance_tree_sizes=False, max_tree_size_ratio=1.0, swap_steps=1):
    """``choose(grew_start, start_size, goal_size, steps, collided)``: the compiled rule's inputs, named."""
    index = SWAP_POLICIES.index(swap_policy)

    def choose(grew_start, start_size, goal_size, steps, collided):
        return choose_tree(
            index,
            balance_tree_sizes,
            max_tree_size_ratio,
            swap_steps,
            grew_start,
            start_size,
            goal_size,
            steps,
            collided,
        )

    return choose


@pytest.mark.parametrize("grew_start", [True, False])
def test_alternate_always_swaps(grew_start):
    choose = tree_rule("alternate")
    for sizes, steps, collided in (((1, 100), 0, False), ((50, 50), 9, True)):
        assert choose(grew_start, *sizes, steps, collided) == (not grew_start, ALTERNATE)


def test_balancing_is_the_balancing_rule_else_the_swap_policy():
    choose = tree_rule("alternate", balance_tree_sizes=True, max_tree_size_ratio=1.0)
    for start_size, goal_size in ((10, 10), (10, 19), (10, 20), (20, 10), (1, 100)):
        for grew_start in (True, False):
            rule = balance_choice(start_size, goal_size, True, 1.0)
            expected = (not grew_start, ALTERNATE) if rule is None else (rule, BALANCE)
            assert choose(grew_start, start_size, goal_size, 0, False) == expected


def test_swap_limit_swaps_exactly_at_swap_steps():
    choose = tree_rule("swap_limit", swap_steps=4)
    for grew_start in (True, False):
        assert [choose(grew_start, 5, 500, steps, True)[0] for steps in range(7)] == [grew_start] * 4 + [
            not grew_start
        ] * 3
    assert choose(True, 1, 1, 4, False)[1] == STEPS


def test_on_collision_swaps_only_after_a_collision():
    choose = tree_rule("on_collision")
    assert choose(True, 5, 500, 99, False) == (True, COLLISION)
    assert choose(False, 5, 500, 99, False) == (False, COLLISION)
    assert choose(True, 5, 5, 0, True) == (False, COLLISION)


def test_tree_choice_resets_its_counts_at_a_swap_and_reports_only_swaps():
    choice = TreeChoice("swap_limit", SwapState(), swap_steps=2)
    assert choice.next_tree(1, 1) == (True, STEPS)  # the first iteration: as if due to swap
    assert (choice.state.steps, choice.state.collided) == (0, False)
    choice.connect_stepped()
    assert choice.next_tree(1, 1) == (True, None)  # one step: no swap
    choice.connect_stepped()
    choice.connect_ended(trapped=True)
    assert choice.next_tree(1, 1) == (False, STEPS)
    assert (choice.state.grew_start, choice.state.steps, choice.state.collided) == (False, 0, False)


def test_unknown_swap_policy_names_the_accepted_ones():
    with pytest.raises(ValueError, match="alternate, swap_limit, on_collision"):
        TreeChoice("sometimes", SwapState())


def test_exhaustion_scale_is_the_lab_formula():
    target = 5
    failures = np.arange(0, 16)
    expected = [0.9 + 0.1 * abs(target - f) / target for f in failures]
    assert exhaustion_scale(failures, target) == pytest.approx(expected)
    assert exhaustion_scale(0, target) == pytest.approx(1.0)
    assert exhaustion_scale(target, target) == pytest.approx(0.9)
    assert exhaustion_scale(2 * target, target) == pytest.approx(1.0)


def test_exhaustion_nearest_minimises_the_scaled_distance():
    distances = np.array([1.00, 1.05, 1.20, 0.99])
    failures = np.array([0, 5, 5, 30])
    # scaled: 1.0, 0.945, 1.08, 0.99 * 1.5 = 1.485 -> node 1 although node 3 is nearest
    assert nearest_by_exhaustion(distances, failures, 5) == 1
    rng = np.random.default_rng(3)
    for _ in range(50):
        distances, failures = rng.uniform(0, 1, 40), rng.integers(0, 20, 40)
        scaled = [d * (0.9 + 0.1 * abs(7 - f) / 7) for d, f in zip(distances, failures)]
        assert nearest_by_exhaustion(distances, failures, 7) == int(np.argmin(scaled))


def test_exhausted_nodes_are_skipped_unless_all_are():
    distances = np.array([0.1, 0.2, 0.3])
    assert nearest_not_exhausted(distances, np.array([15, 14, 0]), 15) == 1
    assert nearest_not_exhausted(distances, np.array([15, 15, 2]), 15) == 2
    assert nearest_not_exhausted(distances, np.array([20, 15, 16]), 15) == 0  # all exhausted: plain nearest


def test_node_quality_is_the_hrrt_formula():
    assert node_quality(2.0, 2.0, 4.0, 0.0) == 1.0  # an optimal node
    assert node_quality(4.0, 2.0, 4.0, 0.0) == 0.0  # the worst node
    assert node_quality(3.0, 2.0, 4.0, 0.0) == pytest.approx(0.5)
    assert node_quality(4.0, 2.0, 4.0, 0.2) == pytest.approx(0.2)  # floored at min_quality
    assert node_quality(2.0, 2.0, 2.0, 0.0) == 1.0  # every node optimal


# -- the policies inside a run: observed through the loop record, on both engines ------------

ENGINES = ["python", "compiled"]


#: The seed of traced runs that do not name one: each test sees the same run every time (an
#: unseeded bug trap is sometimes solved in a dozen iterations, too few to show a rule at work).
TRACE_SEED = 2


def traced_run(problem: str, engine: str = "python", **params):
    """Solve ``problem`` on ``engine`` (seeded: :data:`TRACE_SEED` unless ``params`` has a seed),
    recording each tree choice and each extension step, in order."""
    ss = get_problem(problem).setup()
    planner = BalancedRRTConnect(ss.getSpaceInformation())
    params = {"seed": TRACE_SEED, **params}
    assert planner.params().setParams({"engine": engine, **{key: str(value) for key, value in params.items()}})
    planner.loop_record = LoopRecord()
    ss.setPlanner(planner)
    assert ss.solve(10.0) == ob.PlannerStatus.EXACT_SOLUTION
    assert planner.stats.engine == engine
    return ss, planner, planner.loop_record


def replay_swaps(record):
    """Per iteration after the first: (grew_start, grow_start, connect steps since the last swap,
    last connect trapped), counted from the steps the record holds."""
    steps_by_iteration = {}
    for step in record.steps:
        steps_by_iteration.setdefault(step.iteration, []).append(step)
    decisions, steps, collided, current = [], 0, False, None
    for choice in record.choices:
        decisions.append((current, choice.grow_start, steps, collided))
        if choice.grow_start != current:
            steps, collided = 0, False
        current = choice.grow_start
        for step in steps_by_iteration.get(choice.iteration, []):
            if step.connect:
                steps += 1
                collided = step.outcome is Grow.TRAPPED
    return decisions[1:]  # the first iteration has no previous tree


@pytest.mark.parametrize("engine", ENGINES)
def test_swap_limit_swaps_after_exactly_swap_steps_connect_steps(engine):
    _ss, planner, record = traced_run("bug_trap", engine, swap_policy="swap_limit", swap_steps=3, balance_tree_sizes=0)
    decisions = replay_swaps(record)
    assert len(decisions) > 20
    for grew_start, grow_start, steps, _ in decisions:
        assert (grow_start != grew_start) == (steps >= 3)
    # what the planner passed to the rule is what the trace counts
    passed = [(choice.steps, choice.collided) for choice in record.choices][1:]
    assert [steps for steps, _ in passed] == [steps for _, _, steps, _ in decisions]
    assert planner.stats.swaps_steps == planner.stats.tree_swaps == sum(g != s for g, s, _, _ in decisions)


@pytest.mark.parametrize("engine", ENGINES)
def test_on_collision_never_swaps_after_a_collision_free_connect(engine):
    _ss, planner, record = traced_run("bug_trap", engine, swap_policy="on_collision", balance_tree_sizes=0)
    decisions = replay_swaps(record)
    swaps = [(grew, grow, collided) for grew, grow, _, collided in decisions]
    assert any(grew != grow for grew, grow, _ in swaps)
    assert any(grew == grow for grew, grow, _ in swaps)  # trapped extensions keep the tree
    assert all((grew != grow) == collided for grew, grow, collided in swaps)
    assert planner.stats.swaps_collision == planner.stats.tree_swaps > 0


def extension_targets(record):
    """(grown tree is the start tree, target) of each iteration's extension step."""
    return [(step.start_tree, step.target) for step in record.steps if not step.connect]


@pytest.mark.parametrize("engine", ENGINES)
def test_strict_goal_ball_never_targets_farther_from_the_goal_than_the_start(engine):
    problem = get_problem("bug_trap")
    _ss, planner, record = traced_run("bug_trap", engine, sample_policy="goal_ball", uniform_rate=0.0)
    start, goal = np.array(problem.start), np.array(problem.goal)
    radius = np.linalg.norm(goal - start)
    targets = extension_targets(record)
    assert sum(grow_start for grow_start, _ in targets) > 10
    for grow_start, target in targets:
        centre = goal if grow_start else start
        assert np.linalg.norm(target - centre) <= radius + 1e-12
    assert planner.stats.sampler_rejections > 0  # the ball does not cover the square


@pytest.mark.parametrize("engine", ENGINES)
def test_goal_bias_targets_the_other_root_at_the_given_rate(engine):
    problem = get_problem("bug_trap")
    _ss, _planner, record = traced_run("bug_trap", engine, sample_policy="goal_bias", goal_bias=0.5, seed=5)
    roots = {True: np.array(problem.goal), False: np.array(problem.start)}
    targets = extension_targets(record)
    at_root = [np.array_equal(target, roots[grow_start]) for grow_start, target in targets]
    n = len(at_root)
    assert n > 50
    assert abs(sum(at_root) / n - 0.5) < 4 * math.sqrt(0.25 / n)  # within 4 standard deviations


def replay_failures(record):
    """Per tree (start: True) and node, the failed extensions the record shows before each step,
    and the nodes each tree had: ``[(step, failures of its tree, nodes of its tree)]``."""
    failures = {True: {}, False: {}}
    nodes = {True: {0}, False: {0}}
    seen = []
    for step in record.steps:
        tree_failures = failures[step.start_tree]
        seen.append((step, dict(tree_failures), set(nodes[step.start_tree])))
        if step.outcome is Grow.TRAPPED:
            tree_failures[step.node] = tree_failures.get(step.node, 0) + 1
        else:
            nodes[step.start_tree].add(step.added)
    return seen


@pytest.mark.parametrize("engine", ENGINES)
def test_exhausted_policy_never_extends_an_exhausted_node(engine):
    _ss, _planner, record = traced_run("bug_trap", engine, nearest_policy="exhausted", exhausted_after=2)
    looked_up = [(step, failures, nodes) for step, failures, nodes in replay_failures(record) if not step.node_given]
    assert len(looked_up) > 10
    exhausted_picks = [failures.get(step.node, 0) >= 2 for step, failures, _ in looked_up]
    assert any(count >= 2 for _, failures, _ in looked_up for count in failures.values())  # nodes do get exhausted
    for (_step, failures, nodes), exhausted in zip(looked_up, exhausted_picks):
        assert not exhausted or all(failures.get(node, 0) >= 2 for node in nodes)


@pytest.mark.parametrize("engine", ENGINES)
def test_failed_extensions_are_counted_per_node(engine):
    _ss, planner, record = traced_run("bug_trap", engine, nearest_policy="exhaustion")
    trapped = sum(1 for step in record.steps if step.outcome is Grow.TRAPPED)
    recorded = sum(int(failures.counts(len(tree)).sum()) for tree, failures in planner._failures.items())
    assert trapped > 0 and recorded == trapped


def test_euclidean_policy_counts_no_failures():
    _ss, planner, _record = traced_run("bug_trap")
    assert all(int(f.counts(len(t)).sum()) == 0 for t, f in planner._failures.items())


def test_neighbour_quality_rejects_samples_unless_min_quality_is_one():
    rejections = []
    for min_quality in (0.0, 1.0):
        ss = get_problem("bug_trap").setup()
        planner = BalancedRRTConnect(ss.getSpaceInformation())
        planner.setSamplePolicy("neighbour_quality")
        planner.setMinQuality(min_quality)
        ss.setPlanner(planner)
        assert ss.solve(10.0) == ob.PlannerStatus.EXACT_SOLUTION
        rejections.append(planner.stats.sampler_rejections)
    assert rejections[0] > 0 and rejections[1] == 0


def test_valid_sampler_policy_draws_from_the_space_informations_sampler():
    problem = get_problem("narrow_gap")
    ss = problem.setup()
    # (an allocator that keeps its samplers, e.g. in a closure, makes a reference cycle
    # through the space information: pass the class)
    ss.getSpaceInformation().setValidStateSamplerAllocator(GaussianValidStateSampler)
    planner = BalancedRRTConnect(ss.getSpaceInformation())
    planner.setSamplePolicy("valid_sampler")
    planner.setUniformRate(0.0)  # (every target from the sampler: with uniform ones a lucky solve may draw none)
    ss.setPlanner(planner)
    assert ss.solve(10.0) == ob.PlannerStatus.EXACT_SOLUTION
    stats = planner.stats
    assert isinstance(planner._valid_sampler, GaussianValidStateSampler)
    assert stats.sampler_checks == planner._valid_sampler.validity_checks > 0
    assert stats.states_checked > stats.sampler_checks
    start = ss.getSpaceInformation().allocState()
    start[0], start[1] = problem.start
    assert_valid_solution(ss, problem.world(), [start], ss.getGoal().isSatisfied)


def test_passage_sampler_in_free_space_falls_back_to_uniform_targets():
    # No obstacles: the passage sampler can never find a state near one (it used to stall the
    # planner until the time limit); every iteration that asks it falls back to a uniform target.
    # uniform_rate 0 makes every iteration ask it: at the default 0.1 an iteration may take a
    # uniform target without asking, and in free space the first iteration already solves.
    space = ob.RealVectorStateSpace(2)
    space.setBounds(0.0, 1.0)
    ss = og.SimpleSetup(space)
    ss.setStateValidityChecker(lambda state: True)
    start, goal = space.allocState(), space.allocState()
    start[0], start[1], goal[0], goal[1] = 0.05, 0.05, 0.95, 0.95
    ss.setStartAndGoalStates(start, goal)
    planner = GaussianPassageRRTConnect(ss.getSpaceInformation())
    assert planner.params().setParam("uniform_rate", "0")
    ss.setPlanner(planner)
    assert ss.solve(5.0) == ob.PlannerStatus.EXACT_SOLUTION
    stats = planner.stats
    assert stats.iterations >= 1 and stats.sampler_rejections == stats.iterations


def test_swaps_by_cause_add_up():
    ss = get_problem("bug_trap").setup()
    planner = BalancedRRTConnect(ss.getSpaceInformation())
    ss.setPlanner(planner)
    assert ss.solve(10.0)
    stats = planner.stats
    assert stats.swaps_balance > 0 and stats.swaps_alternate > 0
    assert stats.swaps_alternate + stats.swaps_balance == stats.tree_swaps
    assert stats.swaps_steps == stats.swaps_collision == stats.sampler_rejections == stats.sampler_checks == 0


# -- presets ----------------------------------------------------------------------------------

LAB_PRESETS = [name for name in PRESETS if name != "BalancedRRTConnect"]


def test_presets_are_named_and_differ_only_in_parameters():
    si = get_problem("open").setup().getSpaceInformation()
    assert len(LAB_PRESETS) == 8
    settings = set()
    for name, planner_class in PRESETS.items():
        planner = planner_class(si)
        assert planner.getName() == name
        assert issubclass(planner_class, BalancedRRTConnect)
        settings.add(tuple(sorted(planner.params().getParams().items())))
    # GaussianPassage differs from a plain valid_sampler run by its sampler, not its parameters
    assert len(settings) == len(PRESETS)


@pytest.mark.parametrize("problem_name", ["narrow_gap", "bug_trap"])
@pytest.mark.parametrize("preset", LAB_PRESETS)
def test_every_preset_solves_with_a_valid_path(preset, problem_name):
    problem = get_problem(problem_name)
    ss = problem.setup()
    planner = PRESETS[preset](ss.getSpaceInformation())
    ss.setPlanner(planner)
    assert ss.solve(20.0) == ob.PlannerStatus.EXACT_SOLUTION
    start = ss.getSpaceInformation().allocState()
    start[0], start[1] = problem.start
    assert_valid_solution(ss, problem.world(), [start], ss.getGoal().isSatisfied)


def test_every_preset_runs_in_ompl_benchmark(tmp_path):
    ss = get_problem("narrow_gap").setup()
    si = ss.getSpaceInformation()
    benchmark = ot.Benchmark(ss, "presets")
    benchmark.addPlanner(og.RRTConnect(si))
    for planner_class in PRESETS.values():
        benchmark.addPlanner(planner_class(si))
    benchmark.benchmark(ot.Request(5.0, 1024.0, 2, 0.05, False, False, False))
    log = tmp_path / "presets.log"
    assert benchmark.saveResultsToFile(str(log))
    planners_run = {p.name: p for p in benchmark.getRecordedExperimentData().planners}
    for name in PRESETS:
        runs = planners_run[f"geometric_{name}"].runs
        assert len(runs) == 2
        assert all(run.to_dict()["solved BOOLEAN"] == "1" for run in runs), name


def test_gaussian_passage_preset_uses_the_passage_sampler():
    ss = get_problem("narrow_gap").setup()
    planner = GaussianPassageRRTConnect(ss.getSpaceInformation())
    # every target the sampler's: with the default uniform_rate, a solve of one iteration whose
    # target was uniform (one in ten) asks the sampler nothing
    assert planner.params().setParam("uniform_rate", "0")
    ss.setPlanner(planner)
    assert ss.solve(10.0)
    assert type(planner._valid_sampler).__name__ == "PassageSampler"
    assert planner.stats.sampler_checks > 0


# -- parameters --------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("name", "value", "accepted"),
    [
        ("swap_policy", "sometimes", ", ".join(SWAP_POLICIES)),
        ("nearest_policy", "closest", "euclidean, exhausted, exhaustion"),
        ("sample_policy", "gaussian", ", ".join(SAMPLE_POLICIES)),
        ("swap_steps", "0", "swap_steps must be an integer >= 1"),
        ("exhausted_after", "-2", "exhausted_after must be an integer >= 1"),
        ("exhaustion_target", "2.5", "1:1:100"),
        ("goal_bias", "1.5", "goal_bias must be a number in [0, 1]"),
        ("min_quality", "-0.1", "min_quality must be a number in [0, 1]"),
    ],
)
def test_bad_policy_values_are_refused_with_what_is_accepted(name, value, accepted, capfd):
    planner = BalancedRRTConnect(get_problem("open").setup().getSpaceInformation())
    before = planner.params().getParams()
    assert planner.params().setParam(name, value) is False
    assert planner.params().getParams() == before
    error = capfd.readouterr().err
    assert name in error and accepted in error


def test_choice_parameters_suggest_their_choices():
    params = BalancedRRTConnect(get_problem("open").setup().getSpaceInformation()).params()
    assert params.getRangeSuggestion("swap_policy") == ",".join(SWAP_POLICIES)
    assert params.getRangeSuggestion("sample_policy") == ",".join(SAMPLE_POLICIES)
    assert params.getRangeSuggestion("nearest_policy") == "euclidean,exhausted,exhaustion"


def test_balance_tree_sizes_and_swap_policy_are_independent_in_any_order():
    """No parameter is an alias of another: a dict of settings gives one planner whatever its order."""
    values = {"swap_policy": "on_collision", "balance_tree_sizes": "1", "max_tree_size_ratio": "0.5"}
    planners_made = []
    for order in (list(values), list(reversed(values))):
        planner = BalancedRRTConnect(get_problem("open").setup().getSpaceInformation())
        assert planner.params().setParams({key: values[key] for key in order})
        planners_made.append(planner.params().getParams())
    assert planners_made[0] == planners_made[1]
    assert planners_made[0]["swap_policy"] == "on_collision" and planners_made[0]["balance_tree_sizes"] == "1"


#: A value other than the default for every parameter of BalancedRRTConnect.
OTHER_VALUES = {
    "range": "0.3",
    "intermediate_states": "1",
    "balance_tree_sizes": "0",
    "max_tree_size_ratio": "0.5",
    "swap_policy": "swap_limit",
    "swap_steps": "4",
    "nearest_policy": "exhaustion",
    "exhausted_after": "3",
    "exhaustion_target": "2",
    "sample_policy": "goal_ball",
    "goal_bias": "0.3",
    "min_quality": "0.2",
    "uniform_rate": "0.4",
    "seed": "9",
    "engine": "python",
}


def test_parameters_in_any_order_make_the_same_planner():
    si = get_problem("open").setup().getSpaceInformation()
    assert set(OTHER_VALUES) == set(BalancedRRTConnect(si).params().getParamNames())
    rng = np.random.default_rng(0)
    names = list(OTHER_VALUES)
    made = set()
    for _ in range(30):
        order = rng.permutation(names)
        subset = order[: rng.integers(1, len(names) + 1)]
        planner = BalancedRRTConnect(si)
        assert planner.params().setParams({name: OTHER_VALUES[name] for name in subset})
        expected = {**BalancedRRTConnect(si).params().getParams(), **{name: OTHER_VALUES[name] for name in subset}}
        assert planner.params().getParams() == expected
        made.add(tuple(sorted(subset)))
    assert len(made) > 20
    for order in itertools.islice(itertools.permutations(names), 0, 5000, 250):  # one at a time, any order
        planner = BalancedRRTConnect(si)
        for name in order:
            assert planner.params().setParam(name, OTHER_VALUES[name])
        assert planner.params().getParams() == {name: OTHER_VALUES[name] for name in names}


@pytest.mark.parametrize("preset", LAB_PRESETS)
def test_a_presets_policy_changes_only_through_its_own_parameters(preset):
    si = get_problem("open").setup().getSpaceInformation()
    policy = PRESETS[preset].POLICIES
    for name, value in OTHER_VALUES.items():
        if name in policy:
            continue
        planner = PRESETS[preset](si)
        assert planner.params().setParam(name, value)
        for policy_name, policy_value in policy.items():
            assert planner.params().getParam(policy_name) == policy_value, (name, policy_name)
    planner = PRESETS["CollisionSwapRRTConnect"](si)
    assert planner.params().setParam("balance_tree_sizes", "1")
    assert planner.getSwapPolicy() == "on_collision"  # balancing joins the preset's rule, not replaces it


# -- connect steps and the nearest policy ---------------------------------------------------


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("policy", NEAREST_POLICIES)
def test_connect_steps_after_the_first_extend_the_node_just_added(policy, engine):
    # a short range: connects take many steps
    _ss, _planner, record = traced_run("maze", engine, nearest_policy=policy, balance_tree_sizes=0, range=0.03)
    firsts, furthers = [], []  # connect steps: was the node handed over (no search)?
    previous = None
    for step in record.steps:
        if step.connect:
            further = previous is not None and previous.connect and previous.iteration == step.iteration
            (furthers if further else firsts).append((step.node_given, step.node, previous.added if further else None))
        previous = step
    assert len(furthers) > 10 and all(given and node == added for given, node, added in furthers)
    assert firsts and not any(given for given, _, _ in firsts)  # the first step asks the policy


def test_exhaustion_can_prefer_an_older_failed_node_to_the_node_just_added():
    """Why a connect's further steps do not ask ``exhaustion``: it can pick the node the step
    before extended, whose step would land on the state just added, again and again."""
    tree = ArrayTree(2)
    old = tree.add(np.array([0.0, 0.0]))
    failures = {tree: NodeFailures()}
    for _ in range(5):
        failures[tree].record(old)
    policy = NearestChoice("exhaustion", failures, exhaustion_target=5)
    target = np.array([1.0, 0.0])
    assert policy.node(tree, target)[0] == old
    fresh = tree.add(np.array([0.05, 0.0]), old)  # the connect's step from ``old`` towards the target
    assert tree.nearest(target)[0] == fresh
    assert policy.node(tree, target)[0] == old  # 1.0 x 0.9 < 0.95 x 1.0: ``old`` again, the same step again


def test_neighbour_quality_asks_the_nearest_policy_it_is_given():
    """The nearest policy reaches neighbour_quality through its context, nothing else."""
    tree, other = ArrayTree(2), ArrayTree(2)
    tree.add(np.array([0.1, 0.1]))
    other.add(np.array([0.9, 0.9]))
    asked = []

    class Finder:
        @staticmethod
        def node(searched, point):
            asked.append(searched is tree)
            return 0, float(np.linalg.norm(point - searched.state(0)))

        @staticmethod
        def failed(searched, node):
            raise AssertionError("neighbour_quality records no failures")

    class Uniform:
        def __init__(self):
            self.rng = np.random.default_rng(1)

        def sample(self):
            return self.rng.random(2)

        @staticmethod
        def distance(a, b):
            return float(np.linalg.norm(a - b))

    context = SampleContext(Uniform(), tree, other, np.random.default_rng(2).random, SamplerCounts(), Finder())
    policy = target_choice("neighbour_quality", context)
    for _ in range(20):
        target, nearest = policy.target(True)
        assert target is not None and nearest == 0
    assert len(asked) == 20 and all(asked)


# -- complete by default ---------------------------------------------------------------------


class _FarSampler:
    """Points whose uniform samples are all far outside any goal ball: (0, 0) and (5, 5) marks."""

    def __init__(self):
        self.far = np.array([5.0, 5.0])

    def sample(self):
        return self.far

    @staticmethod
    def distance(a, b):
        return float(np.linalg.norm(a - b))


@pytest.mark.parametrize("rate", [0.0, 0.1, 0.5])
def test_goal_ball_takes_a_uniform_target_at_the_uniform_rate(rate):
    start, goal = ArrayTree(2), ArrayTree(2)
    start.add(np.array([0.0, 0.0]))
    goal.add(np.array([1.0, 0.0]))
    counts = SamplerCounts()
    context = SampleContext(_FarSampler(), start, goal, np.random.default_rng(4).random, counts, uniform_rate=rate)
    policy = target_choice("goal_ball", context)
    n = 2000
    uniform = sum(policy.target(True)[0] is not None for _ in range(n))  # the ball rejects every far point
    assert abs(uniform / n - rate) <= 4 * math.sqrt(rate * (1 - rate) / n)
    assert counts.rejections == (n - uniform) * SAMPLE_ATTEMPTS


def test_control_chosen_solves_what_stock_solves_and_the_strict_rule_cannot():
    ss = TWIN_POCKETS.setup()
    ss.setPlanner(og.RRTConnect(ss.getSpaceInformation()))
    assert ss.solve(10.0) == ob.PlannerStatus.EXACT_SOLUTION
    for seed in (1, 2, 3):
        ss = TWIN_POCKETS.setup()
        planner = PRESETS["ControlChosenRRTConnect"](ss.getSpaceInformation())
        planner.setSeed(seed)
        ss.setPlanner(planner)
        assert ss.solve(30.0) == ob.PlannerStatus.EXACT_SOLUTION
        start = ss.getSpaceInformation().allocState()
        start[0], start[1] = TWIN_POCKETS.start
        assert_valid_solution(ss, TWIN_POCKETS.world(), [start], ss.getGoal().isSatisfied)
    # the strict rule keeps each tree inside the ball around the other root: never solved
    ss = TWIN_POCKETS.setup()
    planner = PRESETS["ControlChosenRRTConnect"](ss.getSpaceInformation())
    planner.setUniformRate(0.0)
    planner.setSeed(1)
    ss.setPlanner(planner)
    iterations = iter(range(3000))
    assert ss.solve(ob.PlannerTerminationCondition(lambda: next(iterations, None) is None)) == ob.PlannerStatus.TIMEOUT
    radius = math.dist(TWIN_POCKETS.start, TWIN_POCKETS.goal)
    for tree, centre in ((planner._start_tree, TWIN_POCKETS.goal), (planner._goal_tree, TWIN_POCKETS.start)):
        assert len(tree) > 50
        assert np.all(np.linalg.norm(tree.states - np.array(centre), axis=1) <= radius + 1e-9)


@pytest.mark.parametrize("preset", ["GaussianPassageRRTConnect", "NeighbourCostRRTConnect"])
def test_presets_solve_the_circle_in_every_run_and_their_strict_rules_do_not(preset):
    """Near obstacles only (the passage sampler), or never from the costliest node (neighbour
    quality with min_quality 0): the far side of the circle is never targeted."""
    ss = circle_setup()
    ss.setPlanner(og.RRTConnect(ss.getSpaceInformation()))
    assert ss.solve(2.0) == ob.PlannerStatus.EXACT_SOLUTION
    for _ in range(5):
        ss = circle_setup()
        planner = PRESETS[preset](ss.getSpaceInformation())
        ss.setPlanner(planner)
        assert ss.solve(2.0) == ob.PlannerStatus.EXACT_SOLUTION
        path = ss.getSolutionPath()
        assert path.check() and all(not 0.5 <= path.getState(i).value <= 1.0 for i in range(path.getStateCount()))
    ss = circle_setup()
    planner = PRESETS[preset](ss.getSpaceInformation())
    planner.setUniformRate(0.0)
    ss.setPlanner(planner)
    iterations = iter(range(500))
    assert ss.solve(ob.PlannerTerminationCondition(lambda: next(iterations, None) is None)) == ob.PlannerStatus.TIMEOUT


def test_the_former_name_of_the_swap_limiter_is_taken_with_a_message(capfd):
    """``balance_steps`` (the swap limiter's former name: it is not balancing) is still accepted,
    as ``swap_limit``, with an OMPL warning naming the new name."""
    planner = BalancedRRTConnect(get_problem("open").setup().getSpaceInformation())
    assert planner.params().setParam("swap_policy", "balance_steps")
    assert planner.getSwapPolicy() == "swap_limit"
    assert "'balance_steps' is now called 'swap_limit'" in capfd.readouterr().err
    planner.setSwapPolicy("balance_steps")
    assert planner.settings.swap_policy == "swap_limit"
