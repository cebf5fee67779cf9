"""Collision-checking speed for the Panda in MotionBenchMaker ``table_pick`` scenes.

Compares, in one run on the same states and edges (and checks the answers agree):

* states/s of a straightforward checker written here (numpy FK per state, every FCL
  transform updated, FCL broad phase for the environment, a Python loop over the
  SRDF-enabled self-collision pairs) against the package's ``CollisionChecker``, called
  one state at a time (OMPL ``isValid``) and in edge-sized batches;
* whole-edge validation: OMPL's default ``DiscreteMotionValidator`` calling the package's
  state checker, against the package's batched discrete ``MotionValidator``
  (``setup_robot(..., motion="discrete")``), on colliding and collision-free edges of
  planner-like length. (The certified validator, which answers a different question, is
  measured in planning by ``bench_certified.py``.)

Usage: ``python benchmarks/bench_validity.py [--scenes 3] [--states 600] [--edges 300]``.
Times are CPU time of the process with the checkers interleaved; figures are medians over
scenes of per-scene ratios.
"""

from __future__ import annotations

import argparse
import time

import fcl
import numpy as np
from ompl import base as ob

from ompl_balance.collision.robots import load_panda_vamp
from ompl_balance.validity import CollisionChecker, StateValidityChecker, setup_robot, space_for
from ompl_balance.worlds.mbm import load_mbm


def straightforward_body_poses(robot, q):
    """Body poses (n, bodies, 4, 4) by plain batched numpy FK: the package's first FK, kept
    here unchanged so that the baseline does not speed up with the package."""
    joints = robot._joints
    source = np.array([j.source for j in joints])
    values = q[:, source] * np.array([j.multiplier for j in joints]) + np.array([j.shift for j in joints])
    axis = np.array([j.axis for j in joints])
    x, y, z = axis.T
    zero = np.zeros_like(x)
    cross = np.stack([zero, -z, y, z, zero, -x, -y, x, zero], axis=-1).reshape(-1, 3, 3)
    revolute = np.array([j.kind == "revolute" for j in joints], dtype=float)[:, None, None]
    motion = np.broadcast_to(np.eye(4), (*values.shape, 4, 4)).copy()
    s, c = np.sin(values)[..., None, None], np.cos(values)[..., None, None]
    motion[..., :3, :3] += revolute * (s * cross + (1.0 - c) * (cross @ cross))
    motion[..., :3, 3] += (1.0 - revolute[:, :, 0]) * values[..., None] * axis
    local = np.array([j.offset for j in joints]) @ motion
    poses = np.empty((len(q), len(joints) + 1, 4, 4))
    poses[:, 0] = np.eye(4)
    for k, joint in enumerate(joints, start=1):
        poses[:, k] = poses[:, joint.parent_body] @ local[:, k - 1]
    return poses


class BaselineChecker:
    """The straightforward per-state checker the package is measured against."""

    def __init__(self, robot, environment):
        self.robot = robot
        self.links = [fcl.CollisionObject(g.shape.fcl_geometry(), fcl.Transform()) for g in robot.geometries]
        self.robot_manager = fcl.DynamicAABBTreeCollisionManager()
        self.robot_manager.registerObjects(self.links)
        self.robot_manager.setup()
        self.obstacles = [
            fcl.CollisionObject(o.shape.fcl_geometry(), fcl.Transform(o.pose[:3, :3], o.pose[:3, 3]))
            for o in environment.obstacles
        ]
        self.environment_manager = fcl.DynamicAABBTreeCollisionManager()
        self.environment_manager.registerObjects(self.obstacles)
        self.environment_manager.setup()
        self.pairs = robot.self_collision_pairs
        self.request = fcl.CollisionRequest()

    def is_valid(self, q) -> bool:
        bodies = straightforward_body_poses(self.robot, np.asarray(q, dtype=float)[None])[0]  # (bodies, 4, 4)
        for obj, geometry in zip(self.links, self.robot.geometries):
            pose = bodies[geometry.body] @ geometry.origin
            obj.setTransform(fcl.Transform(pose[:3, :3], pose[:3, 3]))
        self.robot_manager.update()
        data = fcl.CollisionData(self.request, fcl.CollisionResult())
        self.robot_manager.collide(self.environment_manager, data, fcl.defaultCollisionCallback)
        if data.result.is_collision:
            return False
        return not any(
            fcl.collide(self.links[a], self.links[b], self.request, fcl.CollisionResult()) for a, b in self.pairs
        )


def timed(function, *args):
    """``(result, seconds)`` of one call, in CPU time of this process (steadier than wall time
    on a shared machine)."""
    start = time.process_time()
    result = function(*args)
    return result, time.process_time() - start


def random_edges(robot, checker, count, length, rng):
    """``count`` edges ``(a, b)`` (dof,) each, from a collision-free state, ``length`` rad long (or cut at the bounds)."""
    edges = []
    while len(edges) < count:
        a = rng.uniform(robot.lower, robot.upper)
        if not checker.is_valid(a):
            continue
        direction = rng.normal(size=robot.dof)
        b = np.clip(a + length * direction / np.linalg.norm(direction), robot.lower, robot.upper)
        edges.append((a, b))
    return edges


def bench_scene(robot, problem, states, edge_count, rng):
    """Per-scene timings and agreement; returns a dict of ratios and absolute figures."""
    environment = problem.environment
    baseline = BaselineChecker(robot, environment)
    checker = CollisionChecker(robot, environment)
    q = rng.uniform(robot.lower, robot.upper, size=(states, robot.dof))

    space = space_for(robot)
    si_package = ob.SpaceInformation(space)
    validity, _motion = setup_robot(si_package, checker, motion="discrete")
    si_package.setup()
    si_discrete = ob.SpaceInformation(space)  # OMPL's default DiscreteMotionValidator
    si_discrete.setStateValidityChecker(StateValidityChecker(si_discrete, checker))
    si_discrete.setup()

    # the three ways interleaved, chunk by chunk, so that the machine's load hits them alike
    # (each way timed per chunk of 20 states, so that the timer's own cost is spread alike)
    chunk_states = [si_package.allocState() for _ in range(20)]
    expected, single, batched = [], [], []
    t_base = t_single = t_batch = 0.0
    for chunk in np.array_split(q, max(1, states // 20)):
        answers, elapsed = timed(lambda chunk=chunk: [baseline.is_valid(x) for x in chunk])
        expected += answers
        t_base += elapsed
        for state, x in zip(chunk_states, chunk):
            space.copyFromReals(state, list(x))
        answers, elapsed = timed(lambda chunk=chunk: [validity.isValid(state) for state in chunk_states[: len(chunk)]])
        single += answers
        t_single += elapsed
        answers, elapsed = timed(checker.check, chunk)
        batched += list(answers)
        t_batch += elapsed
    expected = np.array(expected)
    assert (np.array(single) == expected).all() and (np.array(batched) == expected).all(), (
        "package checker disagrees with the baseline"
    )

    length = 0.2 * space.getMaximumExtent()  # RRT-Connect's default range
    edges = random_edges(robot, checker, edge_count, length, rng)
    s1, s2 = si_package.allocState(), si_package.allocState()
    results = {"discrete": ([], []), "package": ([], [])}
    for a, b in edges:  # the two validators alternate edge by edge
        space.copyFromReals(s1, list(a))
        space.copyFromReals(s2, list(b))
        for name, si in (("discrete", si_discrete), ("package", si_package)):
            answer, elapsed = timed(si.checkMotion, s1, s2)
            results[name][0].append(answer)
            results[name][1].append(elapsed)
    results = {name: (np.array(answers), np.array(elapsed)) for name, (answers, elapsed) in results.items()}
    free = results["discrete"][0]
    assert (results["package"][0] == free).all(), "batched motion validator disagrees with OMPL's discrete validator"
    t_discrete, t_package = results["discrete"][1], results["package"][1]
    return {
        "invalid_fraction": 1.0 - expected.mean(),
        "baseline_us": 1e6 * t_base / states,
        "single_us": 1e6 * t_single / states,
        "batch_us": 1e6 * t_batch / states,
        "single_speedup": t_base / t_single,
        "batch_speedup": t_base / t_batch,
        "edges_colliding": int((~free).sum()),
        "edge_speedup_free": t_discrete[free].sum() / t_package[free].sum(),
        "edge_speedup_colliding": t_discrete[~free].sum() / t_package[~free].sum(),
        "edge_speedup_all": t_discrete.sum() / t_package.sum(),
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", type=int, default=3, help="table_pick problems to use")
    parser.add_argument("--states", type=int, default=600, help="random states per scene")
    parser.add_argument("--edges", type=int, default=300, help="random edges per scene")
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    robot = load_panda_vamp()
    problems = load_mbm("table_pick", robot.joint_names)[: args.scenes]
    rng = np.random.default_rng(args.seed)
    rows = []
    for problem in problems:
        row = bench_scene(robot, problem, args.states, args.edges, rng)
        rows.append(row)
        print(f"table_pick {problem.id}: " + ", ".join(f"{k} {v:.3g}" for k, v in row.items()), flush=True)
    median = {k: float(np.median([r[k] for r in rows])) for k in rows[0]}
    print(
        f"\nPanda (VAMP model, {len(robot.self_collision_pairs)} self-collision pairs), "
        f"{len(problems)} table_pick scenes, {args.states} random states and {args.edges} edges each; medians:"
    )
    print(
        f"  states: baseline {median['baseline_us']:.0f} us/state; package one by one {median['single_us']:.0f} us "
        f"({median['single_speedup']:.2f}x), in batches of 20 {median['batch_us']:.0f} us ({median['batch_speedup']:.2f}x); "
        f"target >= 5x and <= 40 us"
    )
    print(
        f"  edges vs OMPL discrete validator: free {median['edge_speedup_free']:.2f}x, colliding "
        f"{median['edge_speedup_colliding']:.2f}x, all {median['edge_speedup_all']:.2f}x; target >= 2x"
    )


if __name__ == "__main__":
    main()
