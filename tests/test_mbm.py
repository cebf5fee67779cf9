"""MotionBenchMaker problems: loading, bad files, and validity of starts and goals with VAMP's Panda."""

import json

import numpy as np
import pytest

from ompl_balance.collision.checker import CollisionChecker
from ompl_balance.worlds.mbm import load_mbm

SCENARIOS = ["table_pick", "table_under_pick", "box", "bookshelf_small"]

PROBLEM = {
    "id": 7,
    "start": [0.0, 0.1, 0.2],
    "goals": [[0.3, 0.4, 0.5]],
    "valid": True,
    "obstacles": [
        {
            "type": "box",
            "name": "table",
            "position": [1, 0, 0],
            "orientation_xyzw": [0, 0, 0, 1],
            "half_extents": [0.5, 0.5, 0.1],
        },
        {
            "type": "cylinder",
            "name": "can",
            "position": [0, 1, 0],
            "orientation_xyzw": [0, 0, 0, 1],
            "radius": 0.1,
            "length": 0.3,
        },
        {"type": "sphere", "name": "ball", "position": [0, 0, 1], "orientation_xyzw": [0, 0, 0, 1], "radius": 0.2},
    ],
}


def write(tmp_path, problem=PROBLEM, joints=("a", "b", "c"), drop=None):
    data = {"scenario": "toy", "joint_names": list(joints), "problems": [json.loads(json.dumps(problem))]}
    if drop:
        *where, field = drop
        target = data["problems"][0]
        for key in where:
            target = target[key]
        del target[field]
    path = tmp_path / "toy.json"
    path.write_text(json.dumps(data))
    return path


def test_load_and_reorder_joints(tmp_path):
    (problem,) = load_mbm(write(tmp_path), ["c", "a", "b"])
    assert problem.id == 7 and problem.scenario == "toy"
    np.testing.assert_array_equal(problem.start, [0.2, 0.0, 0.1])
    np.testing.assert_array_equal(problem.goals, [[0.5, 0.3, 0.4]])
    obstacles = problem.environment.obstacles
    assert [o.name for o in obstacles] == ["table", "can", "ball"]
    assert obstacles[0].shape.dims == (0.5, 0.5, 0.1)  # half extents kept as half extents
    assert obstacles[1].shape.dims == (0.1, 0.3)
    np.testing.assert_array_equal(obstacles[0].pose[:3, 3], [1, 0, 0])


@pytest.mark.parametrize(
    "drop, name",
    [
        (("goals",), "goals"),
        (("obstacles", 1, "radius"), "radius"),
        (("obstacles", 0, "orientation_xyzw"), "orientation_xyzw"),
    ],
)
def test_missing_field_is_named(tmp_path, drop, name):
    with pytest.raises(ValueError, match=f"problem 7.*'{name}'"):
        load_mbm(write(tmp_path, drop=drop))


def test_unknown_joint_names(tmp_path):
    with pytest.raises(ValueError, match="'elbow'"):
        load_mbm(write(tmp_path), ["a", "b", "elbow"])


def test_bad_values(tmp_path):
    bad = dict(PROBLEM, start=[0.0, float("nan"), 0.2])
    with pytest.raises(ValueError, match="start"):
        load_mbm(write(tmp_path, problem=bad))
    bad = dict(PROBLEM, obstacles=[dict(PROBLEM["obstacles"][0], type="cone")])
    with pytest.raises(ValueError, match=r"'table'.*cone"):
        load_mbm(write(tmp_path, problem=bad))
    (tmp_path / "broken.json").write_text("{")
    with pytest.raises(ValueError, match=r"broken\.json"):
        load_mbm(tmp_path / "broken.json")


@pytest.mark.parametrize("scenario", SCENARIOS)
def test_starts_and_goals_valid_with_vamp_panda(scenario):
    from ompl_balance.collision.robots import load_panda_vamp

    robot = load_panda_vamp()
    problems = load_mbm(scenario, robot.joint_names)
    assert len(problems) == 100
    bad_start, no_goal = [], []
    for problem in problems:
        checker = CollisionChecker(robot, problem.environment)
        if not checker.is_valid(problem.start):
            bad_start.append(problem.id)
        if not checker.check(problem.goals).any():
            no_goal.append(problem.id)
    assert not bad_start and not no_goal, (
        f"{scenario}: invalid starts {bad_start}, problems without a valid goal {no_goal}"
    )


def test_simple_setup_refuses_a_robot_with_another_joint_count(tmp_path):
    from ompl_balance.collision.robots import load_panda_vamp

    (problem,) = load_mbm(write(tmp_path))  # three joints
    robot = load_panda_vamp()  # seven
    with pytest.raises(ValueError, match=r"toy problem 7: its configurations have 3 joint values but robot .* has 7"):
        problem.simple_setup(robot)


def test_ompl_2d_resources_load_by_name_as_from_their_files():
    from ompl_balance.worlds.ompl_2d import RESOURCES, load_circles, load_environment, load_queries

    assert load_environment("env1") == load_environment(RESOURCES / "env1.txt")
    assert load_environment("env1").width == 15
    assert load_circles("circle_obstacles").circles == load_circles(RESOURCES / "circle_obstacles.txt").circles
    assert load_queries("circle_queries") == load_queries(RESOURCES / "circle_queries.txt")
    with pytest.raises(ValueError, match="neither a shipped resource"):
        load_environment("env9")
