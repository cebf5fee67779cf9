"""Rigid bodies: planning, per-check cost and certified motions, each against stock or plain in one run.

1. **Planning**: stock ``og.RRTConnect`` and ``BalancedRRTConnect`` (the compiled engine, which
   calls the checker's kernels, and ``engine=python``) on the shipped problems, with
   the same checker and the certified motion validator (each run a fresh checker), runs
   interleaved; per problem and planner: success, median time (failed runs count with the
   limit), median states checked, motions checked and tree nodes, the ratios to stock, and how
   many returned paths collide under a dense re-check (FCL on every pair, ``prefilter=False``, at
   poses along OMPL's interpolation between which no point of the body moves more than ``--step``
   times its reach).
2. **Per check**: the package's checker against the plain FCL checker a user writes (the robot and
   the world each one BVH model, one ``fcl.collide`` per state after ``fcl.Transform`` of the
   state), on the same random states in the bounds, rounds interleaved; microseconds per check,
   the ratio, and the share the compiled screening decides without FCL. The plain checker tests
   meshes, so it misses a body inside a box obstacle; the package's boxes are FCL's solids.
3. **Certified against discrete**: stock ``og.RRTConnect`` with the certified and the discrete
   validator (OMPL's ``validSegmentCount`` states per motion, at OMPL's default resolution),
   interleaved and paired: run ``i`` of both validators starts from OMPL's seed ``i``, so both
   draw the same samples and their trees differ only where the validators' answers do (a
   run's time varies a hundredfold from seed to seed on the harder problems, which unpaired runs
   leave in the ratio); median and total planning time, their ratios, the median of the
   per-seed ratios, and paths colliding in the re-check.

With ``OMPLAPP_RESOURCES`` naming a copy of OMPL.app's ``resources`` folder, sections 2 and 3 also
run on ``--omplapp`` problems (default: Easy, cubicles, Twistycool, alpha-1.5; ``--omplapp-runs``
runs each in section 3).

Run: ``python benchmarks/bench_rigid.py [--runs 10] [--problems se3_room,se3_slot] [--sections 1,2,3]
[--states 3000] [--step 0.002] [--omplapp 3D/Easy,3D/cubicles] [--omplapp-runs 4]``
"""

from __future__ import annotations

import argparse
import itertools
import math
import os
import platform
import statistics
import time
from importlib import metadata
from pathlib import Path

import fcl
import numpy as np
from cells import medians, ratios, success
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou
from scipy.spatial.transform import Rotation

from ompl_balance import BalancedRRTConnect
from ompl_balance.bench.execution import seed_ompl
from ompl_balance.collision.rigid.checker import RigidBodyChecker
from ompl_balance.collision.rigid.motion import interpolate_many, motion_split
from ompl_balance.collision.rigid.view import UNDECIDED, state_status
from ompl_balance.core.counting import measured_solve
from ompl_balance.validity import rigid_state_values
from ompl_balance.worlds.omplapp import load_omplapp
from ompl_balance.worlds.rigid import RIGID_PROBLEMS, RigidBodyProblem, rigid_problem


def python_engine(si: ob.SpaceInformation) -> BalancedRRTConnect:
    planner = BalancedRRTConnect(si)
    planner.setEngine("python")
    return planner


PLANNERS = {
    "RRTConnect": og.RRTConnect,
    "BalancedRRTConnect": BalancedRRTConnect,
    "Balanced, engine=python": python_engine,
}
OMPLAPP = ("3D/Easy", "3D/cubicles", "3D/Twistycool", "3D/alpha-1.5")


def dense_collisions(problem: RigidBodyProblem, states: np.ndarray, step: float) -> int:
    """Motions of the path ``states`` with a colliding pose at most ``step`` times the body's reach
    of travel apart (FCL on every pair, no screening)."""
    reference = RigidBodyChecker(problem.body, problem.environment, prefilter=False)
    reach = problem.body.reach
    colliding = 0
    for a, b in itertools.pairwise(states):
        translation, angle, _ = motion_split(a, b)
        count = max(1, math.ceil((translation + angle * reach) / (step * reach)))
        poses = np.empty((count + 1, len(a)))
        interpolate_many(a, b, np.arange(count + 1) / count, poses)
        colliding += not reference.check(poses).all()
    return colliding


def plan(problem: RigidBodyProblem, planner: str, motion: str, time_limit: float, step: float) -> dict:
    """One planning run and the dense re-check of its path."""
    ss = problem.simple_setup(motion)
    si = ss.getSpaceInformation()
    instance = PLANNERS[planner](si)
    ss.setPlanner(instance)
    run = measured_solve(ss, time_limit)  # (on the engine the planner names, loaded first)
    if planner == "RRTConnect":
        data = ob.PlannerData(si)
        instance.getPlannerData(data)
        nodes = data.numVertices()
    else:
        nodes = instance.stats.start_tree_size + instance.stats.goal_tree_size
    colliding = 0
    if run.solved:
        path = ss.getSolutionPath()
        states = np.array(
            [rigid_state_values(path.getState(i), problem.body.state_size) for i in range(path.getStateCount())]
        )
        colliding = dense_collisions(problem, states, step)
    return {
        "solved": run.solved,
        "time": run.time,
        "states": run.work.states_checked,
        "motions": run.work.motions_checked,
        "nodes": nodes,
        "colliding": colliding,
    }


def planning(problems: list[str], runs: int, step: float) -> None:
    print("\n## 1. BalancedRRTConnect (both engines) against stock RRTConnect (certified motions)\n")
    print("| problem | planner | success | median time (s) | states checked | motions | nodes | colliding paths "
          "| time ratio | states ratio | nodes ratio |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    keys = ("time", "states", "motions", "nodes")
    for name in problems:
        problem = rigid_problem(name)
        results: dict[str, list[dict]] = {p: [] for p in PLANNERS}
        for _ in range(runs):
            for planner in PLANNERS:
                results[planner].append(plan(problem, planner, "certified", float(problem.time_limit or 10.0), step))
        median = medians(results, keys)
        for planner, planner_runs in results.items():
            ratio = ratios(median[planner], median["RRTConnect"])
            solved = [r for r in planner_runs if r["solved"]]
            print(
                f"| {name} | {planner} | {success(planner_runs):.0%} | {median[planner]['time']:.3f} "
                f"| {median[planner]['states']:.0f} | {median[planner]['motions']:.0f} | {median[planner]['nodes']:.0f} "
                f"| {sum(1 for r in solved if r['colliding'])}/{len(solved)} | {ratio['time']:.2f} "
                f"| {ratio['states']:.2f} | {ratio['nodes']:.2f} |",
                flush=True,
            )


class PlainChecker:
    """The checker a user writes with FCL: robot and world one BVH model each, one collide per state."""

    def __init__(self, problem: RigidBodyProblem):
        self.problem = problem
        robot = np.concatenate(
            [np.asarray(p.shape.trimesh().triangles) @ p.pose[:3, :3].T + p.pose[:3, 3] for p in problem.body.parts]
        )
        world = np.concatenate(
            [
                np.asarray(o.shape.trimesh().triangles) @ o.pose[:3, :3].T + o.pose[:3, 3]
                for o in problem.environment.obstacles
            ]
        )
        self.robot, self.world = fcl.CollisionObject(_bvh(robot)), fcl.CollisionObject(_bvh(world))
        self.request = fcl.CollisionRequest()

    def is_valid(self, state: np.ndarray) -> bool:
        axes = len(self.problem.low)
        if not (np.all(self.problem.low <= state[:axes]) and np.all(state[:axes] <= self.problem.high)):
            return False
        if axes == 2:
            half = 0.5 * state[2]
            transform = fcl.Transform(
                np.array([math.cos(half), 0.0, 0.0, math.sin(half)]), np.array([state[0], state[1], 0.0])
            )
        else:
            transform = fcl.Transform(np.array([state[6], state[3], state[4], state[5]]), state[:3])
        self.robot.setTransform(transform)
        return fcl.collide(self.robot, self.world, self.request, fcl.CollisionResult()) == 0


def _bvh(triangles: np.ndarray) -> fcl.BVHModel:
    model = fcl.BVHModel()
    model.beginModel(3 * len(triangles), len(triangles))
    model.addSubModel(triangles.reshape(-1, 3), np.arange(3 * len(triangles)).reshape(-1, 3))
    model.endModel()
    return model


def random_states(problem: RigidBodyProblem, count: int, seed: int) -> list[np.ndarray]:
    rng = np.random.default_rng(seed)
    positions = rng.uniform(problem.low, problem.high, size=(count, len(problem.low)))
    if problem.space == "SE2":
        rows = np.hstack([positions, rng.uniform(-math.pi, math.pi, size=(count, 1))])
    else:
        rows = np.hstack([positions, Rotation.random(count, random_state=seed).as_quat()])
    return [np.ascontiguousarray(row) for row in rows]


def per_check(problems: dict[str, RigidBodyProblem], count: int, rounds: int = 5) -> None:
    print("\n## 2. Per validity check: the package's checker against a plain FCL checker\n")
    print("| problem | package (us) | plain (us) | ratio | decided without FCL | answers differ |")
    print("|---|---|---|---|---|---|")
    for name, problem in problems.items():
        ours, plain = problem.checker(), PlainChecker(problem)
        states = random_states(problem, count, seed=1)
        times = {"package": 0.0, "plain": 0.0}
        for _ in range(rounds):  # interleaved
            began = time.perf_counter()
            answers = [ours.is_valid(s) for s in states]
            times["package"] += time.perf_counter() - began
            began = time.perf_counter()
            plain_answers = [plain.is_valid(s) for s in states]
            times["plain"] += time.perf_counter() - began
        kernel = ours.view
        undecided = sum(1 for s in states if state_status(kernel, s) == UNDECIDED)
        per = {k: v / (rounds * count) * 1e6 for k, v in times.items()}
        differ = sum(a != b for a, b in zip(answers, plain_answers))
        print(
            f"| {name} | {per['package']:.1f} | {per['plain']:.1f} | {per['package'] / per['plain']:.2f} "
            f"| {1 - undecided / count:.0%} | {differ} of {count} |",
            flush=True,
        )


def certified_against_discrete(problems: dict[str, RigidBodyProblem], runs: int, step: float) -> None:
    if not problems:
        return
    print(f"\n## 3. Certified against discrete motions: stock RRTConnect's planning time ({runs} runs)\n")
    print(
        "| problem | validator | success | median time (s) | total time (s) | colliding paths | median ratio "
        "| total ratio | per-seed ratio (median) |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    for name, problem in problems.items():
        limit = float(problem.time_limit or 10.0)
        results: dict[str, list[dict]] = {"certified": [], "discrete": []}
        for seed in range(1, runs + 1):
            for motion, motion_runs in results.items():
                seed_ompl(seed)  # both validators' run from the same seed: paired
                motion_runs.append(plan(problem, "RRTConnect", motion, limit, step))
        discrete = results["discrete"]
        for motion, motion_runs in results.items():
            solved = [r for r in motion_runs if r["solved"]]
            median = statistics.median(r["time"] for r in motion_runs)
            total = sum(r["time"] for r in motion_runs)
            per_seed = statistics.median(r["time"] / d["time"] for r, d in zip(motion_runs, discrete, strict=True))
            print(
                f"| {name} | {motion} | {success(motion_runs):.0%} | {median:.3f} | {total:.1f} "
                f"| {sum(1 for r in solved if r['colliding'])}/{len(solved)} "
                f"| {median / statistics.median(r['time'] for r in discrete):.2f} "
                f"| {total / sum(r['time'] for r in discrete):.2f} | {per_seed:.2f} |",
                flush=True,
            )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=10, help="runs per planner (validator) and problem (default 10)")
    parser.add_argument("--problems", default=",".join(RIGID_PROBLEMS), help="shipped problems (default: all)")
    parser.add_argument("--sections", default="1,2,3", help="which sections to run (default 1,2,3)")
    parser.add_argument("--states", type=int, default=3000, help="random states per problem in section 2")
    parser.add_argument(
        "--step", type=float, default=0.002, help="re-check: largest move of a point / the body's reach"
    )
    parser.add_argument("--omplapp", default=",".join(OMPLAPP), help="OMPL.app problems, with OMPLAPP_RESOURCES")
    parser.add_argument("--omplapp-runs", type=int, default=4, help="runs per validator on OMPL.app problems")
    args = parser.parse_args()
    ou.RNG.setSeed(1)
    ou.setLogLevel(ou.LOG_ERROR)
    sections = {int(s) for s in args.sections.split(",")}
    shipped = args.problems.split(",")
    began = time.perf_counter()
    print(
        f"{args.runs} runs each, each problem's own time limit; Python {platform.python_version()}, "
        f"ompl {metadata.version('ompl')}, python-fcl {metadata.version('python-fcl')}"
    )
    omplapp: dict[str, RigidBodyProblem] = {}
    resources = os.environ.get("OMPLAPP_RESOURCES")
    if resources:
        for name in args.omplapp.split(","):
            cfg = Path(resources) / f"{name}.cfg"
            if cfg.is_file():
                omplapp[f"OMPL.app {Path(name).name}"] = load_omplapp(cfg, validate=False)
    if 1 in sections:
        planning(shipped, args.runs, args.step)
    if 2 in sections:
        per_check({**{name: rigid_problem(name) for name in shipped}, **omplapp}, args.states)
    if 3 in sections:
        certified_against_discrete({name: rigid_problem(name) for name in shipped}, args.runs, args.step)
        certified_against_discrete(omplapp, args.omplapp_runs, args.step)
    print(f"\nwhole script: {time.perf_counter() - began:.0f} s")


if __name__ == "__main__":
    main()
