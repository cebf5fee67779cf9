"""Benchmark runner: experiment files, seeded runs in their own processes, OMPL logs and database, summaries."""

from __future__ import annotations

import dataclasses
import json
import math
import shutil
import sqlite3
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest
from ompl import geometric as og

from ompl_balance.bench.compare import bench, compare_experiment, parse_planners
from ompl_balance.bench.errors import ExperimentError
from ompl_balance.bench.experiment import Experiment, PlannerSpec, run_seed
from ompl_balance.bench.experiment_file import load_experiment
from ompl_balance.bench.isolation import run_isolated
from ompl_balance.bench.logs import write_logs
from ompl_balance.bench.problems import ProblemSpec, problem_by_name
from ompl_balance.bench.progress_sampler import ProgressSampler
from ompl_balance.bench.summary import summarize
from ompl_balance.cli import main
from ompl_balance.worlds.boxes import Problem

REPO = Path(__file__).resolve().parents[1]

GOOD = """\
name = "tiny"
runs = 2
time_limit = 1.0
seed = 7

[[problems]]
builtin = "open"

[[planners]]
name = "RRTConnect"
params = { range = 0.3 }

[[planners]]
name = "BalancedRRTConnect"
label = "Balanced r=0.5"
params = { max_tree_size_ratio = 0.5 }
"""


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "experiment.toml"
    path.write_text(text)
    return path


def deterministic(record: dict) -> tuple:
    """What a seeded run must repeat exactly (everything but times and memory)."""
    properties = {
        k: v for k, v in record["properties"].items() if not k.startswith(("time", "simplification time", "memory"))
    }
    return (
        record["problem"],
        record["planner"],
        record["run"],
        record["seed"],
        record["status"],
        sorted(properties.items()),
    )


# -- experiment files ---------------------------------------------------------------------


def test_experiment_file_reads_planners_params_and_seeds(tmp_path):
    experiment = load_experiment(write(tmp_path, GOOD))
    assert [p.label for p in experiment.planners] == ["RRTConnect", "Balanced r=0.5"]
    assert experiment.planners[1].params == {"max_tree_size_ratio": "0.5"}
    tasks = experiment.tasks()
    assert len(tasks) == 1 * 2 * 2
    assert len({t.seed for t in tasks}) == 4  # every run its own seed...
    assert tasks[0].seed == run_seed(7, "open", "RRTConnect", 0)  # ...from the experiment seed and its coordinates
    assert tasks[0].hard_limit == 2 * 1.0 + experiment.hard_limit_margin


@pytest.mark.parametrize(
    ("change", "expected"),
    [
        (
            ('name = "RRTConnect"', 'name = "RRTConnectt"'),
            ["planners[0].name", "line 10", "unknown planner 'RRTConnectt'", "BalancedRRTConnect"],
        ),
        (
            ("max_tree_size_ratio = 0.5", "max_tree_ratio = 0.5"),
            ["planners[1].params.max_tree_ratio", "line 16", "max_tree_size_ratio"],
        ),
        (
            ("max_tree_size_ratio = 0.5", "max_tree_size_ratio = -1"),
            ["planners[1].params.max_tree_size_ratio", "line 16"],
        ),
        (("range = 0.3", "rang = 0.3"), ["planners[0].params.rang", "line 11", "range"]),
        (("runs = 2", "runs = -3"), ["runs", "line 2", "whole number >= 1"]),
        (("time_limit = 1.0", "time_limit = 0"), ["time_limit", "line 3", "positive"]),
        (
            ('builtin = "open"', 'mbm = "nowhere.json"\nrobot = "."'),
            ["problems[0].mbm", "line 7", "nor a file", "nowhere.json"],
        ),
        (('builtin = "open"', 'builtin = "opne"'), ["problems[0].builtin", "line 7", "narrow_gap"]),
        (("seed = 7", "sede = 7"), ["sede", "line 4", "unknown key"]),
        (("runs = 2", "runs = 2 ]"), ["not valid TOML", "line 2"]),
    ],
)
def test_bad_experiment_files_fail_before_any_run_naming_key_and_line(tmp_path, capsys, change, expected):
    path = write(tmp_path, GOOD.replace(*change))
    with pytest.raises(ExperimentError) as error:
        load_experiment(path)
    for text in expected:
        assert text in str(error.value)
    out = tmp_path / "out"
    assert main(["bench", str(path), "-o", str(out), "--no-progress"]) == 2
    assert expected[0] in capsys.readouterr().err
    assert not (out / "results.jsonl").exists()  # nothing ran


def test_mbm_problems_expand_ids_and_ranges(tmp_path):
    text = GOOD.replace('builtin = "open"', 'mbm = "table_pick"\nids = [3, "10-12"]')
    experiment = load_experiment(write(tmp_path, text))
    assert [p.name for p in experiment.problems] == [
        "table_pick.003",
        "table_pick.010",
        "table_pick.011",
        "table_pick.012",
    ]
    with pytest.raises(ExperimentError, match=r"problems\[0\].ids: ids \[101\] not in the file"):
        load_experiment(write(tmp_path, text.replace('"10-12"', '"10-101"')))


def test_mbm_problems_select_the_motion_validator(tmp_path):
    """Certified motions by default; ``motion = "discrete"`` installs OMPL-style discrete checking."""
    from ompl_balance.validity import CertifiedMotionValidator, MotionValidator

    def problem(extra: str) -> str:
        return GOOD.replace('builtin = "open"', 'mbm = "box"\nids = [1]' + extra)

    for extra, validator in (("", CertifiedMotionValidator), ('\nmotion = "discrete"', MotionValidator)):
        ss = load_experiment(write(tmp_path, problem(extra))).problems[0].build()
        assert type(ss.getSpaceInformation().getMotionValidator()) is validator
    with pytest.raises(ExperimentError, match=r"problems\[0\].motion: must be one of certified, discrete"):
        load_experiment(write(tmp_path, problem('\nmotion = "exact"')))


def test_rigid_problems_by_name_or_omplapp_file_with_their_motion_validator(tmp_path):
    """``rigid = NAME`` builds the shipped problem (certified motions unless ``motion`` says
    otherwise); an OMPL.app ``.cfg`` file is read relative to the experiment file; a name that is
    neither is refused naming the key, the line and what is accepted."""
    from test_omplapp import SE3_LINES, box, collada, write_cfg

    from ompl_balance.validity import RigidBodyCertifiedMotionValidator, RigidBodyMotionValidator

    def problem(source: str, extra: str = "") -> str:
        return GOOD.replace('builtin = "open"', f'rigid = "{source}"' + extra)

    for extra, validator in (
        ("", RigidBodyCertifiedMotionValidator),
        ('\nmotion = "discrete"', RigidBodyMotionValidator),
    ):
        spec = load_experiment(write(tmp_path, problem("se2_slot", extra))).problems[0]
        assert spec.name == "se2_slot"
        ss = spec.build()
        assert type(ss.getSpaceInformation().getMotionValidator()) is validator
        assert ss.getSpaceInformation().getStateSpace().getDimension() == 3  # SE(2)
    collada(tmp_path / "robot.dae", *box([-1.0, -0.5, -0.25], [1.0, 0.5, 0.25]))
    collada(tmp_path / "world.dae", *box([-5.0, -5.0, 4.0], [5.0, 5.0, 5.0]))
    cfg = write_cfg(tmp_path, SE3_LINES)
    spec = load_experiment(write(tmp_path, problem(cfg.name, '\nname = "mine"'))).problems[0]
    assert (spec.name, spec.source, len(spec.data)) == ("mine", str(cfg.resolve()), 16)
    assert spec.build().getSpaceInformation().getStateSpace().getDimension() == 6  # SE(3)
    with pytest.raises(
        ExperimentError, match=r"line 7: problems\[0\].rigid: .se3_nowhere. is neither a shipped problem \(se2_slot"
    ):
        load_experiment(write(tmp_path, problem("se3_nowhere")))
    assert problem_by_name("se3_room").kind == "rigid"
    assert {"se2_bugtrap", "se3_room"} <= {p.name for p in compare_experiment().problems}


def test_planner_list_syntax_of_compare():
    specs = parse_planners("RRTConnect,BalancedRRTConnect[max_tree_size_ratio=0.5;range=0.1],RRT")
    assert [s.label for s in specs] == ["RRTConnect", "BalancedRRTConnect[max_tree_size_ratio=0.5;range=0.1]", "RRT"]
    assert specs[1].params == {"max_tree_size_ratio": "0.5", "range": "0.1"}
    with pytest.raises(ExperimentError, match=r"planners\[0\].params.nope"):
        compare_experiment(["open"], parse_planners("RRT[nope=1]"))


# -- runs -----------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def tiny_sweep(tmp_path_factory):
    """GOOD plus stock RRT, on two problems, run with two jobs."""
    out = tmp_path_factory.mktemp("tiny")
    experiment = Experiment(
        name="tiny",
        problems=(ProblemSpec("open", "builtin", "open"), ProblemSpec("narrow_gap", "builtin", "narrow_gap")),
        planners=(
            PlannerSpec("RRTConnect", "RRTConnect", params={"range": "0.3"}),
            PlannerSpec("Balanced r=0.5", "BalancedRRTConnect", params={"max_tree_size_ratio": "0.5"}),
            PlannerSpec("RRT", "RRT"),
        ),
        runs=2,
        time_limit=10.0,
        seed=7,
    )  # a limit no run should reach: limited runs do not repeat
    records = bench(experiment, out, jobs=2, progress=False)
    return experiment, out, records


def test_sweep_records_every_run_once_with_counters(tiny_sweep):
    experiment, _out, records = tiny_sweep
    assert sorted((r["problem"], r["planner"], r["run"]) for r in records) == sorted(t.key for t in experiment.tasks())
    assert all(r["status"] == "EXACT_SOLUTION" and r["properties"]["solved BOOLEAN"] == 1 for r in records)
    for record in records:
        properties = record["properties"]
        assert properties["validity checks INTEGER"] > 0 and properties["motion checks INTEGER"] > 0
        assert properties["simplified solution length REAL"] <= properties["solution length REAL"] + 1e-9
    balanced = [r for r in records if r["planner"] == "Balanced r=0.5"]
    assert all(r["properties"]["iterations INTEGER"] >= 1 and "tree swaps INTEGER" in r["properties"] for r in balanced)
    assert all(r["params"]["max_tree_size_ratio"] == "0.5" for r in balanced)
    assert all(r["params"]["range"] == "0.3" for r in records if r["planner"] == "RRTConnect")


def test_a_run_re_executed_alone_repeats_its_result(tiny_sweep):
    experiment, _, records = tiny_sweep
    by_key = {(r["problem"], r["planner"], r["run"]): r for r in records}
    for task in [t for t in experiment.tasks() if t.problem.name == "narrow_gap" and t.run == 1]:
        assert deterministic(run_isolated(task)) == deterministic(by_key[task.key])


def test_the_warm_up_solve_is_neither_timed_nor_counted(tiny_sweep):
    """BalancedRRTConnect samples from the run's seed in numpy, so its timed solve does the same
    work with and without the warm-up solve before it: any leak of the warm-up's work would show."""
    experiment, _, _ = tiny_sweep
    task = next(
        t for t in experiment.tasks() if t.planner.name == "BalancedRRTConnect" and t.problem.name == "narrow_gap"
    )
    assert task.warm_up
    warm, cold = run_isolated(task), run_isolated(dataclasses.replace(task, warm_up=False))
    for name in ("validity checks INTEGER", "motion checks INTEGER", "iterations INTEGER", "solution length REAL"):
        assert warm["properties"][name] == cold["properties"][name], name


def test_progress_sampling_starts_at_begin_so_its_thread_start_is_not_timed():
    """The sampler's thread runs from the ``with`` block's start but takes no sample before
    ``begin()`` (the runner's clock start), and its sample times count from ``begin()``."""
    period = 0.01
    reads = []
    sampler = ProgressSampler({"iterations INTEGER": lambda: str(len(reads.append(0) or reads))}, period=period)
    with sampler:
        assert sampler._thread.is_alive()
        time.sleep(5 * period)
        assert sampler.samples == [] and reads == []  # waiting for begin()
        began = sampler.begin()
        deadline = time.perf_counter() + 30.0
        while len(sampler.samples) < 2 and time.perf_counter() < deadline:
            time.sleep(period)
    ended = time.perf_counter()  # after the block: its thread took every sample before this
    assert not sampler._thread.is_alive()
    assert sampler.names == ["iterations INTEGER", "time REAL"]
    times = [float(sample[1]) for sample in sampler.samples]
    assert len(times) >= 2
    assert period <= times[0] and times == sorted(times) and times[-1] <= ended - began
    assert [int(sample[0]) for sample in sampler.samples] == list(range(1, len(times) + 1))


def test_no_sample_is_kept_from_after_the_end_of_the_solve():
    """The solve has returned at ``end()``: the thread's second round, held (by the check it
    makes first) until after ``end()``, takes a sample that is not one of the solve's."""
    rounds, in_second_round, ended = [], threading.Event(), threading.Event()

    def check() -> None:
        rounds.append(None)
        if len(rounds) == 2:
            in_second_round.set()
            ended.wait(30.0)

    sampler = ProgressSampler({"iterations INTEGER": lambda: "1"}, period=0.001, check=check)
    with sampler:
        sampler.begin()
        assert in_second_round.wait(30.0)
        elapsed = sampler.end()
        ended.set()
    times = [float(sample[1]) for sample in sampler.samples]
    assert len(times) == 1 and times[0] <= elapsed  # the first round's sample only


def test_a_sampler_never_begun_ends_with_its_block():
    sampler = ProgressSampler({"iterations INTEGER": lambda: "0"}, period=0.01)
    with sampler:
        pass
    assert not sampler._thread.is_alive() and sampler.samples == []


def test_a_sweep_tells_the_user_nothing_about_seeds_it_sets_correctly(tmp_path):
    """Each run seeds OMPL in a process forked from the forkserver, whose warm-up has already
    drawn seeds; OMPL would log an error per run that the seed cannot make it deterministic,
    which it does (the runs repeat: test_a_run_re_executed_alone_repeats_its_result). Run as a
    user runs it, the sweep's standard error says nothing of it."""
    path = write(tmp_path, GOOD.replace("runs = 2", "runs = 1"))
    result = subprocess.run(
        [sys.executable, "-m", "ompl_balance.cli", "bench", str(path), "-o", str(tmp_path / "out"), "--no-progress"],
        check=False,
        capture_output=True,
        text=True,
        timeout=600,
        cwd=REPO,
    )
    assert result.returncode == 0, result.stderr
    records = [json.loads(line) for line in (tmp_path / "out" / "results.jsonl").read_text().splitlines()]
    assert sorted(r["planner"] for r in records) == ["Balanced r=0.5", "RRTConnect"]
    assert "Random number generation already started" not in result.stderr + result.stdout


def test_rerun_runs_nothing_and_more_runs_add_only_the_missing(tmp_path):
    experiment = small()
    first = bench(experiment, tmp_path, progress=False)
    lines = (tmp_path / "results.jsonl").read_text().splitlines()
    assert sorted(map(deterministic, bench(experiment, tmp_path, progress=False))) == sorted(map(deterministic, first))
    assert (tmp_path / "results.jsonl").read_text().splitlines() == lines  # nothing run again
    more = bench(small(runs=3), tmp_path, progress=False)
    added = (tmp_path / "results.jsonl").read_text().splitlines()[len(lines) :]
    assert sorted((r["problem"], r["planner"], r["run"]) for r in map(json.loads, added)) == sorted(
        (p, q, 2) for p in ("open", "corner") for q in ("RRTConnect", "Balanced")
    )
    assert len(more) == 12


def corner_world(goal: float) -> og.SimpleSetup:
    """The open unit square from (0.1, 0.1) to (goal, goal) (a problem factory for the tests)."""
    return Problem("corner", "open square", (), (0.1, 0.1), (goal, goal)).setup()


def small(**changes) -> Experiment:
    """Two problems x two planners x two runs, a second each; ``changes`` replace fields."""
    fields = {
        "name": "small",
        "problems": (
            ProblemSpec("open", "builtin", "open"),
            ProblemSpec("corner", "factory", "test_benchmark:corner_world", args={"goal": 0.9}),
        ),
        "planners": (
            PlannerSpec("RRTConnect", "RRTConnect", params={"range": "0.1"}),
            PlannerSpec("Balanced", "BalancedRRTConnect"),
        ),
        "runs": 2,
        "time_limit": 5.0,
        "seed": 2,
    }
    return Experiment(**{**fields, **changes})


@pytest.fixture(scope="module")
def small_sweep(tmp_path_factory):
    out = tmp_path_factory.mktemp("small")
    return out, bench(small(), out, progress=False)


ALL_CELLS = {(p, q) for p in ("open", "corner") for q in ("RRTConnect", "Balanced")}


@pytest.mark.parametrize(
    ("changes", "changed_cells", "message"),
    [
        (
            {
                "planners": (
                    PlannerSpec("RRTConnect", "RRTConnect", params={"range": "0.3"}),
                    PlannerSpec("Balanced", "BalancedRRTConnect"),
                )
            },
            {("open", "RRTConnect"), ("corner", "RRTConnect")},
            "planner 'RRTConnect': params {'range': '0.1'} -> {'range': '0.3'}",
        ),
        (
            {
                "planners": (
                    PlannerSpec("RRTConnect", "RRTConnect", params={"range": "0.1"}),
                    PlannerSpec("Balanced", "RRT"),
                )
            },
            {("open", "Balanced"), ("corner", "Balanced")},
            "planner 'Balanced': name 'BalancedRRTConnect' -> 'RRT'",
        ),
        (
            {
                "problems": (
                    ProblemSpec("open", "builtin", "open"),
                    ProblemSpec("corner", "factory", "test_benchmark:corner_world", args={"goal": 0.8}),
                )
            },
            {("corner", "RRTConnect"), ("corner", "Balanced")},
            "problem 'corner': args {'goal': 0.9} -> {'goal': 0.8}",
        ),
        ({"time_limit": 4.0}, ALL_CELLS, "time_limit 5.0 -> 4.0"),
        ({"seed": 3}, ALL_CELLS, "seed 2 -> 3"),
    ],
    ids=["params", "planner", "problem", "time limit", "seed"],
)
def test_a_changed_definition_runs_exactly_the_changed_cells_again(
    small_sweep, tmp_path, changes, changed_cells, message
):
    before, first = small_sweep
    shutil.copytree(before, tmp_path, dirs_exist_ok=True)
    notices: list[str] = []
    experiment = small(**changes)
    records = bench(experiment, tmp_path, progress=False, notify=notices.append)
    tasks = {task.key: task for task in experiment.tasks()}
    assert sorted((r["problem"], r["planner"], r["run"]) for r in records) == sorted(tasks)
    earlier = {(r["problem"], r["planner"], r["run"]): r for r in first}
    for record in records:
        key = (record["problem"], record["planner"], record["run"])
        assert record["definition"] == tasks[key].definition  # nothing reported from another definition
        if key[:2] in changed_cells:
            assert record["definition"] != earlier[key]["definition"]
        else:
            assert record == earlier[key]  # kept as it was
    superseded = [json.loads(line) for line in (tmp_path / "superseded" / "results.jsonl").read_text().splitlines()]
    assert sorted(json.dumps(r, sort_keys=True) for r in superseded) == sorted(
        json.dumps(r, sort_keys=True) for r in first if (r["problem"], r["planner"]) in changed_cells
    )
    stored = [json.loads(line) for line in (tmp_path / "results.jsonl").read_text().splitlines()]
    assert sorted(map(deterministic, stored)) == sorted(map(deterministic, records))  # no stale record left
    (notice,) = notices
    assert message in notice and f"{2 * len(changed_cells)} runs of {len(changed_cells)} cells" in notice
    with sqlite3.connect(tmp_path / "benchmark.db") as db:
        assert db.execute("SELECT COUNT(*) FROM runs").fetchone()[0] == 8
        settings = "".join(row[0] for row in db.execute("SELECT settings FROM plannerConfigs"))
    if "planners" in changes and "range" in message:
        assert "range = 0.3" in settings and "range = 0.1" not in settings
        assert all(r["params"]["range"] == "0.3" for r in records if r["planner"] == "RRTConnect")


def test_experiment_files_use_only_the_data_shipped_with_the_package():
    files = [*sorted((REPO / "experiments").glob("*.toml")), REPO / "examples" / "experiment.toml"]
    assert len(files) >= 4
    for path in files:
        experiment = load_experiment(path)
        for problem in experiment.problems:
            assert problem.robot == "" and not Path(problem.source).is_absolute(), (path, problem.name)
    outside = ("../" + "shared", "shared" + "/data")  # the data folder beside a development checkout
    for folder in ("ompl_balance", "tests", "experiments", "examples"):
        for path in (REPO / folder).rglob("*"):
            if path.is_file() and path.suffix in (".py", ".toml", ".md", ".json", ".txt"):
                text = path.read_text(errors="replace")
                assert not any(word in text for word in outside), path


def test_ompl_statistics_script_reads_the_logs(tiny_sweep, tmp_path):
    _experiment, out, records = tiny_sweep
    logs = sorted((out / "logs").glob("*.log"))
    assert [log.name for log in logs] == ["tiny.narrow_gap.log", "tiny.open.log"]
    database = tmp_path / "ompl.db"
    script = Path(sys.executable).with_name("ompl_benchmark_statistics")
    command = [str(script)] if script.exists() else [sys.executable, "-m", "ompl.ompl_benchmark_statistics"]
    subprocess.run([*command, *map(str, logs), "-d", str(database)], check=True, capture_output=True)
    with sqlite3.connect(database) as db:
        assert db.execute("SELECT COUNT(*) FROM experiments").fetchone()[0] == 2
        assert db.execute("SELECT COUNT(*) FROM runs").fetchone()[0] == len(records) == 12
        per_planner = dict(
            db.execute(
                "SELECT name, COUNT(*) FROM runs JOIN plannerConfigs ON plannerid = plannerConfigs.id GROUP BY name"
            )
        )
        assert per_planner == {"RRTConnect": 4, "Balanced r=0.5": 4, "RRT": 4}
        settings = dict(db.execute("SELECT name, settings FROM plannerConfigs"))
        assert "max_tree_size_ratio = 0.5" in settings["Balanced r=0.5"] and "seed = run" in settings["Balanced r=0.5"]
        assert "range = 0.3" in settings["RRTConnect"]
        columns = {row[1] for row in db.execute("PRAGMA table_info(runs)")}
        assert {
            "time",
            "solved",
            "status",
            "solution_length",
            "solution_segments",
            "simplified_solution_length",
            "graph_states",
            "iterations",
            "start_tree_size",
            "goal_tree_size",
            "tree_swaps",
            "validity_checks",
            "motion_checks",
            "distance_queries",
            "seed",
        } <= columns
        checks = db.execute("SELECT SUM(validity_checks) FROM runs").fetchone()[0]
        assert checks == sum(r["properties"]["validity checks INTEGER"] for r in records)
    assert (out / "benchmark.db").is_file()


def test_summary_ratios_are_to_the_baseline(tiny_sweep):
    experiment, out, records = tiny_sweep
    summaries = summarize(records, "RRTConnect", [p.label for p in experiment.planners])
    assert [(s.problem, s.planner) for s in summaries][:3] == [
        ("open", "RRTConnect"),
        ("open", "Balanced r=0.5"),
        ("open", "RRT"),
    ]
    for s in summaries:
        assert s.time.interval[0] <= s.time.median <= s.time.interval[1]
        assert s.checks.interval[0] <= s.checks.median <= s.checks.interval[1]
        if s.planner == "RRTConnect":
            assert s.checks.ratio == 1.0
        else:
            base = next(b for b in summaries if b.problem == s.problem and b.planner == "RRTConnect")
            assert s.checks.ratio == pytest.approx(s.checks.median / base.checks.median)
            assert s.checks.ratio_interval[0] <= s.checks.ratio <= s.checks.ratio_interval[1]
    table = (out / "summary.md").read_text()
    assert "### open" in table and "### narrow_gap" in table and "| RRT | 2 | 100% |" in table
    assert (out / "summary.csv").read_text().count("\n") == 1 + 6


def test_plot_writes_boxplots_curves_and_trees(tiny_sweep):
    pytest.importorskip("matplotlib")
    from ompl_balance.bench.plots import grow_trees, plot_folder

    _, out, _ = tiny_sweep
    written = plot_folder(out, tree_iterations=40)
    names = {path.name for path in written}
    assert {"open.png", "narrow_gap.png", "success_vs_time.png", "trees_narrow_gap.png", "summary.csv"} <= names
    assert all(path.stat().st_size > 0 for path in written)
    data, iterations = grow_trees("bug_trap", balance=True, iterations=40)
    assert iterations == 40  # stopped at the asked iteration
    tags = {data.getVertex(i).getTag() for i in range(data.numVertices())}
    assert tags == {1, 2}


def test_write_logs_leaves_blank_what_a_crashed_run_lacks(tiny_sweep, tmp_path):
    experiment, _, records = tiny_sweep
    crashed = {
        **records[0],
        "run": 9,
        "status": "CRASH",
        "error": "killed by SIGSEGV",
        "properties": {"time REAL": 0.5, "status ENUM": 7, "solved BOOLEAN": 0},
    }
    log = write_logs(experiment, [records[0], crashed], tmp_path)[0].read_text()
    run_lines = [line for line in log.splitlines() if line.endswith("; ")]
    assert len(run_lines) == 2 and run_lines[0].count(";") == run_lines[1].count(";")
    assert "; ; " in run_lines[1]  # blanks where the crashed run has no value


def summary_record(planner: str, solved: bool, time_s: float, checks: int, problem: str = "p") -> dict:
    """A run's record as far as the summary reads it."""
    return {
        "problem": problem,
        "planner": planner,
        "error": "",
        "properties": {
            "time REAL": time_s,
            "solved BOOLEAN": int(solved),
            "validity checks INTEGER": checks,
            "graph states INTEGER": checks // 10,
        },
    }


def test_pooling_by_scenario_makes_one_cell_per_scenario_and_planner():
    from ompl_balance.bench.summary import pooled_by_scenario, summarize

    records = [
        summary_record(planner, True, t, 10, problem=f"box.{i:03d}")
        for i in (1, 2)
        for planner, t in (("A", 1.0), ("B", 0.5))
    ]
    cells = summarize(pooled_by_scenario(records), baseline="A", order=["A", "B"])
    assert [(c.problem, c.planner, c.runs) for c in cells] == [("box", "A", 2), ("box", "B", 2)]
    assert cells[1].time.ratio == 0.5


def test_summary_medians_and_ratios_are_of_solved_runs_only():
    from ompl_balance.bench.summary import format_markdown

    records = [
        summary_record("stock", True, 0.2, 400),
        summary_record("stock", True, 0.4, 600),
        summary_record("stock", False, 5.0, 90000),  # ran until the limit: not what a solution cost
        summary_record("fails fast", False, 0.0001, 1),
        summary_record("fails fast", False, 0.0001, 1),
        summary_record("half", True, 0.1, 100),
        summary_record("half", False, 5.0, 50000),
    ]
    cells = {c.planner: c for c in summarize(records, "stock", ["stock", "fails fast", "half"])}
    stock = cells["stock"]
    assert (stock.time.median, stock.checks.median, stock.checks.ratio) == (pytest.approx(0.3), 500, 1.0)
    assert cells["half"].success == 0.5
    assert cells["half"].time.ratio == pytest.approx(0.1 / 0.3)
    assert cells["half"].checks.ratio == pytest.approx(100 / 500)
    failed = cells["fails fast"]
    assert failed.success == 0.0
    assert all(math.isnan(value) for m in (failed.time, failed.checks, failed.nodes) for value in (m.median, m.ratio))
    table = format_markdown(list(cells.values()), "stock")
    assert table.splitlines()[0].startswith("Success over all runs; times, validity checks and nodes are medians")
    assert "| fails fast | 2 | 0% | - | - | - | - | - | - |" in table.splitlines()


def test_no_ratio_to_a_baseline_that_solved_no_run():
    records = [summary_record("stock", False, 5.0, 9000), summary_record("other", True, 0.5, 300)]
    other = summarize(records, "stock", ["stock", "other"])[1]
    assert other.checks.median == 300 and math.isnan(other.checks.ratio) and math.isnan(other.time.ratio)
