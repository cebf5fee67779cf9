"""Benchmark runner under failure and in parallel: crashes and hangs, a killed sweep resumed, Dask = local pool."""

from __future__ import annotations

import ctypes
import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numba
import pytest
from fresh_process import with_ctrl_c_as_in_a_terminal
from ompl import base as ob
from ompl import geometric as og
from test_benchmark import deterministic

from ompl_balance.bench.compare import bench
from ompl_balance.bench.experiment import Experiment, PlannerSpec
from ompl_balance.bench.isolation import preload_modules, start_forkserver
from ompl_balance.bench.problems import ProblemSpec

REPO = Path(__file__).resolve().parents[1]
TESTS = Path(__file__).resolve().parent


# -- planner factories that fail (called in the run's process) ------------------------------


def segfaulting_planner(si: ob.SpaceInformation) -> ob.Planner:
    ctypes.string_at(0)  # reads address 0: SIGSEGV
    raise AssertionError("unreachable")


class HangingPlanner(ob.Planner):
    """Ignores its termination condition."""

    def __init__(self, si):
        super().__init__(si, "Hanging")

    def solve(self, ptc):
        while True:
            time.sleep(0.05)


def hanging_planner(si: ob.SpaceInformation) -> ob.Planner:
    return HangingPlanner(si)


def test_crash_and_hang_are_recorded_and_the_sweep_goes_on(tmp_path):
    experiment = Experiment(
        name="failing",
        problems=(ProblemSpec("open", "builtin", "open"),),
        planners=(
            PlannerSpec("RRTConnect", "RRTConnect"),
            PlannerSpec("segfault", factory="test_benchmark_runs:segfaulting_planner"),
            PlannerSpec("hang", factory="test_benchmark_runs:hanging_planner"),
        ),
        runs=2,
        time_limit=0.5,
        seed=3,
        # a run's process imports this test module (and pytest) to build its planner: seconds on a
        # loaded machine, which the hard limit (2 x 0.5 + 4 s) must leave the segfaulting runs
        hard_limit_margin=4.0,
    )
    start_forkserver(preload_modules(experiment))  # (numba compiles the kernels it preloads on a first use)
    began = time.perf_counter()
    records = bench(experiment, tmp_path, jobs=2, progress=False)
    assert time.perf_counter() - began < 60  # the hung runs were killed at 2 x 0.5 + 4 s
    status = {(r["planner"], r["run"]): r["status"] for r in records}
    assert status == {
        ("RRTConnect", 0): "EXACT_SOLUTION",
        ("RRTConnect", 1): "EXACT_SOLUTION",
        ("segfault", 0): "CRASH",
        ("segfault", 1): "CRASH",
        ("hang", 0): "CRASH",  # killed at the hard limit: OMPL's Benchmark called an overrun a crash
        ("hang", 1): "CRASH",
    }
    errors = {r["planner"]: r["error"] for r in records}
    assert "SIGSEGV" in errors["segfault"] and "hard limit" in errors["hang"]
    assert all(r["properties"]["solved BOOLEAN"] == 0 for r in records if r["planner"] != "RRTConnect")
    log = (tmp_path / "logs" / "failing.open.log").read_text()
    assert "\nsegfault\n" in log and "\nhang\n" in log  # failed runs are in the OMPL log too
    assert "2 crashed" in (tmp_path / "summary.md").read_text()
    assert all(r["properties"]["status ENUM"] == 7 for r in records if r["planner"] != "RRTConnect")


# -- a run that solves, then stalls in path simplification ----------------------------------

#: Set by StraightLinePlanner's solve: the validity checker stalls from then on (simplification).
_SOLVED = [False]


def stalling_after_solve_world() -> og.SimpleSetup:
    """An open square whose validity checker sleeps a minute per state once the planner solved."""

    def is_valid(state: ob.State) -> bool:
        if _SOLVED[0]:
            time.sleep(60.0)
        return True

    space = ob.RealVectorStateSpace(2)
    space.setBounds(0.0, 1.0)
    ss = og.SimpleSetup(space)
    ss.setStateValidityChecker(is_valid)
    start, goal = space.allocState(), space.allocState()
    start[0], start[1], goal[0], goal[1] = 0.1, 0.1, 0.9, 0.9
    ss.setStartAndGoalStates(start, goal)
    return ss


class StraightLinePlanner(ob.Planner):
    """Solves at once with a three-state straight line from the start to the goal."""

    def __init__(self, si):
        super().__init__(si, "StraightLine")

    def solve(self, ptc):
        pdef = self.getProblemDefinition()
        si = self.getSpaceInformation()
        start, goal = pdef.getStartState(0), pdef.getGoal().getState()
        middle = si.allocState()
        si.getStateSpace().interpolate(start, goal, 0.5, middle)
        path = og.PathGeometric(si)
        for state in (start, middle, goal):
            path.append(state)
        pdef.addSolutionPath(path, False, 0.0, self.getName())
        _SOLVED[0] = True
        return ob.PlannerStatus(ob.PlannerStatus.EXACT_SOLUTION)


def straight_line_planner(si: ob.SpaceInformation) -> ob.Planner:
    return StraightLinePlanner(si)


def test_a_run_that_solved_then_overran_in_simplification_is_recorded_as_solved(tmp_path):
    """Killed at the hard limit while simplifying: the record is the solve's (solved, its time and
    length), not a crash of the planner, and its note says that simplification did not return."""
    experiment = Experiment(
        name="stall",
        problems=(ProblemSpec("stall", "factory", "test_benchmark_runs:stalling_after_solve_world"),),
        planners=(PlannerSpec("line", factory="test_benchmark_runs:straight_line_planner"),),
        runs=1,
        time_limit=0.5,
        seed=3,
        hard_limit_margin=4.0,  # (the run's process imports this module: seconds on a loaded machine)
        warm_up=False,
    )
    start_forkserver(preload_modules(experiment))
    began = time.perf_counter()
    (record,) = bench(experiment, tmp_path, jobs=1, progress=False)
    assert time.perf_counter() - began < 40  # killed at 2 x 0.5 + 4 s, not after the checker's minute
    assert record["status"] == "EXACT_SOLUTION" and record["error"] == ""
    properties = record["properties"]
    assert properties["solved BOOLEAN"] == 1
    assert properties["solution length REAL"] == pytest.approx(0.8 * 2**0.5)
    assert properties["time REAL"] < 0.5
    assert properties["simplification time REAL"] > 0.5  # it ran until the kill
    assert "simplified solution length REAL" not in properties
    assert "path simplification" in record["note"] and "did not return" in record["note"]
    assert "crashed" not in (tmp_path / "summary.md").read_text()


@numba.njit
def _free_beside_a_wall(x: float, y: float) -> bool:  # (not cached: compiled at its first call in a process)
    return not (0.45 < x < 0.55 and y < 0.8)


def lazily_compiled_world() -> og.SimpleSetup:
    """A square with a wall whose validity checker calls a numba function compiled at its first call."""
    space = ob.RealVectorStateSpace(2)
    space.setBounds(0.0, 1.0)
    ss = og.SimpleSetup(space)
    ss.setStateValidityChecker(lambda state: bool(_free_beside_a_wall(state[0], state[1])))
    start, goal = space.allocState(), space.allocState()
    start[0], start[1], goal[0], goal[1] = 0.1, 0.1, 0.9, 0.1
    ss.setStartAndGoalStates(start, goal)
    return ss


@pytest.mark.parametrize("warm_up, margin", [(False, 5.0), (True, 5.0), (False, 0.0)])
def test_a_solve_during_which_numba_compiled_is_timed_again(tmp_path, warm_up, margin):
    """Without a warm-up the run's first solve compiles the checker's numba function: the run is
    timed again in its process, and its record is the second solve's (no compiling in its time),
    with a note; the warm-up compiles it, and the run is timed once. Without a hard limit margin
    to time it again in, the record is the first solve's, with a note that its time includes it."""
    experiment = Experiment(
        name="lazy",
        problems=(ProblemSpec("lazy", "factory", "test_benchmark_runs:lazily_compiled_world"),),
        planners=(PlannerSpec("RRTConnect", "RRTConnect"),),
        runs=1,
        time_limit=5.0,
        seed=3,
        hard_limit_margin=margin,
        warm_up=warm_up,
    )
    start_forkserver(preload_modules(experiment))
    (record,) = bench(experiment, tmp_path, jobs=1, progress=False)
    properties, note = record["properties"], record.get("note", "")
    assert record["status"] == "EXACT_SOLUTION" and properties["solved BOOLEAN"] == 1
    timed_again = re.search(r"timed again: numba compiled for (\d+) ms during its first solve", note)
    includes = re.search(r"numba compiled for (\d+) ms during this solve, which its time includes", note)
    if warm_up:
        assert timed_again is None and includes is None, note
    elif margin > 0.0:
        assert timed_again is not None and includes is None, note  # the second solve compiled nothing
        assert properties["time REAL"] * 1e3 < int(timed_again.group(1))  # a 2-D solve, without the compiling
    else:
        assert timed_again is None and includes is not None, note
        assert properties["time REAL"] * 1e3 >= int(includes.group(1))


RESUME_TOML = """\
name = "resume"
runs = 8
time_limit = 10.0
seed = 11

[[problems]]
builtin = "open"

[[problems]]
builtin = "narrow_gap"

[[planners]]
name = "RRTConnect"

[[planners]]
name = "BalancedRRTConnect"
"""


def _bench_command(experiment: Path, out: Path) -> list[str]:
    return [sys.executable, "-m", "ompl_balance.cli", "bench", str(experiment), "-o", str(out), "--no-progress"]


def test_a_killed_sweep_resumes_without_repeating_or_losing_runs(tmp_path):
    experiment, out = tmp_path / "resume.toml", tmp_path / "out"
    experiment.write_text(RESUME_TOML)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(REPO), str(TESTS), os.environ.get("PYTHONPATH", "")])}
    sweep = subprocess.Popen(
        _bench_command(experiment, out),
        env=env,
        start_new_session=True,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    results = out / "results.jsonl"
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and (not results.exists() or len(results.read_text().splitlines()) < 5):
        time.sleep(0.05)
    os.killpg(sweep.pid, signal.SIGKILL)  # the sweep, its forkserver and the run in flight
    sweep.wait()
    before = results.read_text().splitlines()
    assert 5 <= len(before) < 32, "the sweep should have been killed mid-way"

    finished = subprocess.run(
        _bench_command(experiment, out), env=env, capture_output=True, text=True, timeout=300, check=False
    )
    assert finished.returncode == 0, finished.stderr
    after = [json.loads(line) for line in results.read_text().splitlines() if line.strip()]
    keys = [(r["problem"], r["planner"], r["run"]) for r in after]
    assert len(keys) == len(set(keys)) == 2 * 2 * 8  # nothing twice, nothing missing
    kept = [json.loads(line) for line in before if line.endswith("}")]
    assert after[: len(kept)] == kept  # what finished before the kill is kept as it was
    assert "32 runs in" in finished.stdout


def test_dask_cluster_gives_the_results_of_the_local_pool(tmp_path, monkeypatch):
    pytest.importorskip("dask.distributed")
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join([str(REPO), str(TESTS), os.environ.get("PYTHONPATH", "")]))
    experiment = Experiment(
        name="same",
        problems=(ProblemSpec("open", "builtin", "open"), ProblemSpec("narrow_gap", "builtin", "narrow_gap")),
        planners=(
            PlannerSpec("RRTConnect", "RRTConnect"),
            PlannerSpec("BalancedRRTConnect", "BalancedRRTConnect"),
            PlannerSpec("alternating", "BalancedRRTConnect", params={"balance_tree_sizes": "0"}),
            # draws from OMPL's RNG (valid-state sampler): repeated by the run's process seed
            PlannerSpec("GaussianPassageRRTConnect", "GaussianPassageRRTConnect"),
        ),
        runs=3,
        time_limit=10.0,
        seed=5,
    )
    local = bench(experiment, tmp_path / "local", jobs=2, progress=False)
    distributed = bench(experiment, tmp_path / "dask", dask="local:2", progress=False)
    assert len(local) == len(distributed) == 24
    assert all(r["status"] == "EXACT_SOLUTION" for r in local + distributed)
    assert sorted(map(deterministic, local)) == sorted(map(deterministic, distributed))
    logs = sorted(p.name for p in (tmp_path / "dask" / "logs").glob("*.log"))
    assert logs == sorted(p.name for p in (tmp_path / "local" / "logs").glob("*.log"))


def _console_script() -> str:
    return str(Path(sys.executable).with_name("ompl-balance"))


def test_compare_interrupted_then_run_again_resumes(tmp_path):
    out = tmp_path / "out"
    command = [_console_script(), "compare", "--problems", "open", "--runs", "20", "-o", str(out), "--no-progress"]
    compare = subprocess.Popen(
        with_ctrl_c_as_in_a_terminal(command),
        start_new_session=True,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    results = out / "results.jsonl"
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and (not results.exists() or len(results.read_text().splitlines()) < 5):
        time.sleep(0.05)
    os.killpg(compare.pid, signal.SIGINT)  # Ctrl-C: the terminal signals the whole foreground group
    _, stderr = compare.communicate(timeout=60)
    before = results.read_text().splitlines()
    assert 5 <= len(before) < 60, f"compare should have been interrupted mid-way: {len(before)} runs; {stderr}"
    assert compare.returncode == 130, stderr
    assert f"the finished runs are kept in {out}; run the same command again to resume" in stderr
    assert "Traceback" not in stderr

    finished = subprocess.run(command, capture_output=True, text=True, timeout=300, check=False)
    assert finished.returncode == 0, finished.stderr
    assert "another definition" not in finished.stderr  # the same command, the same runs: resumed
    after = [json.loads(line) for line in results.read_text().splitlines()]
    keys = [(r["problem"], r["planner"], r["run"]) for r in after]
    assert len(keys) == len(set(keys)) == 3 * 20
    assert after[: len(before)] == [json.loads(line) for line in before]
    assert f"60 runs in {out}" in finished.stdout


DECOY = """\
from pathlib import Path

Path(__file__).resolve().parents[1].joinpath("DECOY_IMPORTED").write_text("a run imported this copy")
"""


def test_runs_import_the_installed_package_not_a_copy_in_the_current_folder(tmp_path):
    (tmp_path / "ompl_balance").mkdir()
    (tmp_path / "ompl_balance" / "__init__.py").write_text(DECOY)
    (tmp_path / "experiment.toml").write_text(
        'name = "decoy"\nruns = 2\ntime_limit = 5.0\n[[problems]]\nmbm = "box"\nids = [1]\n'
        '[[problems]]\nbuiltin = "open"\n[[planners]]\nname = "BalancedRRTConnect"\n'
    )
    finished = subprocess.run(
        [_console_script(), "bench", "experiment.toml", "-o", "out", "--no-progress"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert finished.returncode == 0, finished.stderr
    assert not (tmp_path / "DECOY_IMPORTED").exists()
    records = [json.loads(line) for line in (tmp_path / "out" / "results.jsonl").read_text().splitlines()]
    assert len(records) == 4 and all(r["status"] == "EXACT_SOLUTION" for r in records)
