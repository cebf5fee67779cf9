"""The ompl-balance command line: compare runs and prints the table; bad options, missing extras
and wrong folders end in one line saying what to do."""

import json
import sqlite3
import subprocess
import sys
import time

import numpy as np
import pytest

from ompl_balance.bench.compare import compare_experiment
from ompl_balance.cli import main


def test_compare_prints_a_table_per_problem(capsys):
    assert main(["compare", "--runs", "2", "--problems", "open,narrow_gap", "--no-progress"]) == 0
    out = capsys.readouterr().out
    assert "### open" in out and "### narrow_gap" in out and "### maze" not in out
    rows = [line for line in out.splitlines() if line.startswith("| ") and "planner" not in line]
    assert len(rows) == 6  # 3 planners x 2 problems
    stock_rows = [row for row in rows if row.startswith("| RRTConnect |")]
    assert len(stock_rows) == 2
    assert all(
        row.count("| 1.00 [1.00, 1.00] |") == 3 for row in stock_rows
    )  # time, checks, nodes: stock is the baseline
    assert all("| 2 | 100% |" in row for row in rows)
    assert out.startswith("experiment seed 1\n")  # the default seed: the same command makes the same runs
    assert "runs in a temporary folder, now deleted (-o OUT keeps" in out


def test_compare_writes_only_its_tables_to_standard_output(tmp_path):
    """OMPL's log lines from the runs' processes (the forkserver's setup logs ``Info:``) go to
    standard error; a fresh process, so that its forkserver starts with this command."""
    done = subprocess.run(
        [sys.executable, "-m", "ompl_balance.cli", "compare", "--problems", "open", "--runs", "1", "--no-progress"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("experiment seed 1\n") and "### open" in done.stdout
    assert not any(line.startswith(("Info:", "Debug:", "Warning:")) for line in done.stdout.splitlines()), done.stdout
    assert "Info:    BalancedRRTConnect: range computed" in done.stderr


def test_compare_runs_motionbenchmaker_panda_problems_by_default(capsys):
    from ompl_balance.cli import build_parser

    defaults = build_parser().parse_args(["compare"]).problems
    assert {"box.001", "bookshelf_small.001", "table_pick.001", "table_under_pick.001"} <= set(defaults)
    assert main(["compare", "--runs", "1", "--problems", "box.001", "--no-progress"]) == 0
    out = capsys.readouterr().out
    assert "### box.001" in out
    rows = [line for line in out.splitlines() if line.startswith("| ") and "planner" not in line]
    assert len(rows) == 3 and all("| 1 | 100% |" in row for row in rows)


def test_compare_takes_stock_planners_and_presets_by_name(capsys):
    args = [
        "compare",
        "--runs",
        "1",
        "--problems",
        "open",
        "--planners",
        "RRT,BalancedRRTConnect[range=0.1]",
        "--no-progress",
    ]
    assert main(args) == 0
    rows = [line for line in capsys.readouterr().out.splitlines() if line.startswith("| ") and "planner" not in line]
    assert [row.split(" | ")[0] for row in rows] == ["| RRT", "| BalancedRRTConnect[range=0.1]"]
    assert all("| 1 | 100% |" in row for row in rows)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["compare", "--runs", "0"], "must be a whole number >= 1"),
        (["compare", "--time-limit", "-1"], "positive number of seconds"),
        (["compare", "--problems", "open,nowhere"], "unknown problem 'nowhere'"),
        (["compare", "--problems", "box.101"], "ids [101] not in the file"),
        (["compare", "--dask", "local:0"], "expected tcp://HOST:PORT or local:N"),
        (["compare", "--jobs", "0"], "must be a whole number >= 1"),
        (["compare", "--runs", "abc"], "--runs: must be a whole number >= 1, got 'abc'"),
        (["compare", "--time-limit", "soon"], "--time-limit: must be a positive number of seconds, got 'soon'"),
        (["compare", "--planners", "RRT[range]"], "cannot read parameter 'range' of 'RRT[range]'"),
        (["compare", "--planners", "RRT[range=0.1;range=0.2]"], "parameter 'range' is given twice"),
        (["gamma", "--eta", "-1"], "--eta: must be a positive number of metres, got '-1'"),
        (["gamma", "--resolution", "-1"], "--resolution: must be a positive number of metres, got '-1'"),
        (["gamma", "--confidence", "1.5"], "--confidence: must be a number between 0 and 1"),
        (["gamma", "--seed", "-2"], "--seed: must be a whole number >= 0, got '-2'"),
    ],
)
def test_bad_options_are_refused_with_a_reason(args, message, capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(args)
    assert exit_info.value.code == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err, err


def test_gamma_prints_the_estimate_for_a_builtin_problem(capsys):
    from ompl_balance.gamma import ball_radius_constant
    from ompl_balance.worlds.occupancy import rooms_grid

    assert main(["gamma", "--problem", "rooms"]) == 0
    out = capsys.readouterr().out
    lines = {line.split()[0]: line.split()[1] for line in out.splitlines() if line.strip()}
    expected = ball_radius_constant(2, rooms_grid().free_area)
    assert float(lines["gamma*"]) == pytest.approx(expected, rel=1e-5)
    rewire_factor = next(line.split()[2] for line in out.splitlines() if line.startswith("OMPL rewire_factor"))
    assert float(rewire_factor) > 0


def _one_line_error(capsys, args, expected):
    assert main(args) == 2
    err = capsys.readouterr().err
    assert expected in err and "Traceback" not in err and len(err.strip().splitlines()) == 1, err


def test_dask_without_dask_is_one_line_naming_the_install(monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "dask.distributed", None)  # import fails as if not installed
    _one_line_error(
        capsys,
        ["compare", "--problems", "open", "--runs", "1", "--dask", "local:1"],
        "pip install 'ompl-balance[distributed]'",
    )


def test_more_jobs_than_cores_warns_once_that_timings_compete(monkeypatch, capsys):
    monkeypatch.setattr("os.cpu_count", lambda: 2)
    args = ["compare", "--problems", "open", "--planners", "RRTConnect", "--runs", "3", "--no-progress"]
    assert main([*args, "--jobs", "3"]) == 0
    warnings = [line for line in capsys.readouterr().err.splitlines() if line.startswith("warning: --jobs")]
    assert warnings == [
        "warning: --jobs 3 is more than this machine's 2 cores: the runs' timings then compete for cores and come "
        "out longer than alone (validity checks stay exact); --jobs 2 or fewer times them fairly"
    ]
    assert main([*args, "--jobs", "2"]) == 0
    assert "warning" not in capsys.readouterr().err


def test_a_dask_scheduler_that_does_not_answer_is_one_line_naming_it(capsys):
    pytest.importorskip("dask.distributed")
    from ompl_balance.bench.scheduling import DASK_CONNECT_TIMEOUT

    began = time.perf_counter()
    _one_line_error(
        capsys,
        ["compare", "--problems", "open", "--runs", "1", "--no-progress", "--dask", "tcp://127.0.0.1:1"],
        "--dask tcp://127.0.0.1:1: no Dask scheduler answered within 5 s",
    )
    assert time.perf_counter() - began < DASK_CONNECT_TIMEOUT + 10


def test_plot_without_matplotlib_is_one_line_naming_the_install(monkeypatch, capsys, tmp_path):
    (tmp_path / "experiment.json").write_text(json.dumps(compare_experiment(["open"], runs=1).as_dict()))
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    _one_line_error(capsys, ["plot", str(tmp_path)], "pip install 'ompl-balance[plot]'")


def test_plot_of_a_folder_that_is_not_an_output_folder_is_one_line(capsys, tmp_path):
    _one_line_error(capsys, ["plot", str(tmp_path / "nowhere")], "is not an output folder (no experiment.json)")
    (tmp_path / "experiment.json").write_text("{not json")
    _one_line_error(capsys, ["plot", str(tmp_path)], "cannot be read as an experiment")


def test_gamma_of_a_grid_without_free_space_says_so(capsys, tmp_path):
    grid = tmp_path / "full.npy"
    np.save(grid, np.ones((10, 10), dtype=bool))
    with pytest.raises(SystemExit) as exit_info:
        main(["gamma", "--grid", str(grid)])
    assert exit_info.value.code == 2
    err = capsys.readouterr().err
    assert "no state is free (every cell occupied)" in err and "Traceback" not in err, err


def test_parameters_in_brackets_may_be_separated_by_commas(capfd):
    args = ["compare", "--runs", "1", "--problems", "open", "--no-progress"]
    assert main([*args, "--planners", "BalancedRRTConnect[range=0.1, max_tree_size_ratio=0.5]"]) == 0
    out = capfd.readouterr().out
    assert "| BalancedRRTConnect[range=0.1, max_tree_size_ratio=0.5] | 1 | 100% |" in out


def test_a_bad_parameter_value_is_one_line_without_ompls_own(capfd):
    args = ["compare", "--runs", "1", "--problems", "open", "--planners", "BalancedRRTConnect[range=abc]"]
    assert main(args) == 2
    err = capfd.readouterr().err
    assert err.strip() == (
        "ompl-balance compare: planners[0].params.range: bad value 'abc' for 'range'; accepted: 0.:1.:10000."
    )


def _record_lines(out):
    return (out / "results.jsonl").read_text().splitlines()


def test_a_problem_dropped_from_compare_leaves_nothing_of_it_in_the_outputs(capsys, tmp_path):
    out = tmp_path / "out"
    args = ["compare", "--runs", "1", "-o", str(out), "--no-progress", "--planners", "RRTConnect"]
    assert main([*args, "--problems", "open,narrow_gap"]) == 0
    assert sorted(p.name for p in (out / "logs").iterdir()) == ["compare.narrow_gap.log", "compare.open.log"]
    assert main(["plot", str(out), "--tree-iterations", "5"]) == 0
    assert (out / "plots" / "narrow_gap.png").is_file()
    assert main([*args, "--problems", "open"]) == 0
    assert [p.name for p in (out / "logs").iterdir()] == ["compare.open.log"]
    assert (out / "superseded" / "logs" / "compare.narrow_gap.log").is_file()
    assert main(["plot", str(out), "--tree-iterations", "5"]) == 0
    assert not any("narrow_gap" in p.name for p in (out / "plots").iterdir())
    assert {"narrow_gap.png", "trees_narrow_gap.png"} <= {p.name for p in (out / "superseded" / "plots").iterdir()}
    with sqlite3.connect(out / "benchmark.db") as db:
        assert db.execute("SELECT name FROM experiments").fetchall() == [("compare.open",)]
    assert "narrow_gap" not in (out / "summary.md").read_text()
    assert main([*args, "--problems", "open,narrow_gap"]) == 0  # back again: its runs were kept
    assert len(_record_lines(out)) == 2
    assert sorted(p.name for p in (out / "logs").iterdir()) == ["compare.narrow_gap.log", "compare.open.log"]


def test_another_experiments_folder_is_refused_and_left_as_it_was(capsys, tmp_path):
    out = tmp_path / "out"
    assert main(["compare", "--runs", "1", "--problems", "open", "-o", str(out), "--no-progress"]) == 0
    before = sorted((path.relative_to(out), path.read_bytes()) for path in out.rglob("*") if path.is_file())
    experiment = tmp_path / "other.toml"
    experiment.write_text('name = "other"\nruns = 1\n[[problems]]\nbuiltin = "open"\n[[planners]]\nname = "RRT"\n')
    _one_line_error(
        capsys,
        ["bench", str(experiment), "-o", str(out), "--no-progress"],
        f"{out}: holds the results of experiment 'compare' (experiment.json), not of 'other': give another folder",
    )
    after = sorted((path.relative_to(out), path.read_bytes()) for path in out.rglob("*") if path.is_file())
    assert after == before


@pytest.mark.parametrize("command", ["compare", "bench"])
def test_output_folders_that_cannot_be_one_are_refused_in_one_line(command, capsys, tmp_path):
    experiment = tmp_path / "tiny.toml"
    experiment.write_text('name = "tiny"\nruns = 1\n[[problems]]\nbuiltin = "open"\n[[planners]]\nname = "RRT"\n')
    start = ["compare", "--runs", "1", "--problems", "open"] if command == "compare" else ["bench", str(experiment)]
    a_file = tmp_path / "a_file"
    a_file.write_text("not a folder")
    (tmp_path / "papers").mkdir()
    (tmp_path / "papers" / "draft.tex").write_text("")
    for out, message in (
        (a_file, "is a file; the output folder (-o) must be a new or empty folder"),
        (a_file / "below", "cannot make the output folder"),
        (tmp_path / "papers", "is not empty and holds no experiment.json"),
    ):
        _one_line_error(capsys, [*start, "-o", str(out), "--no-progress"], message)
    assert a_file.read_text() == "not a folder" and [p.name for p in (tmp_path / "papers").iterdir()] == ["draft.tex"]


def test_plot_refuses_a_baseline_that_is_not_a_planner(capsys, tmp_path):
    out = tmp_path / "out"
    assert main(["compare", "--runs", "1", "--problems", "open", "-o", str(out), "--no-progress"]) == 0
    capsys.readouterr()
    _one_line_error(capsys, ["plot", str(out), "--baseline", "Nope"], "baseline: 'Nope' is not a planner of")


def test_compare_turns_the_warm_up_off_as_an_experiment_file_does(capsys, tmp_path):
    out = tmp_path / "out"
    args = ["compare", "--runs", "1", "--problems", "open", "--planners", "PRM", "-o", str(out), "--no-progress"]
    assert main([*args, "--no-warm-up"]) == 0
    assert json.loads((out / "experiment.json").read_text())["warm_up"] is False
    assert main(args) == 0  # warm-up on (the default): another definition of the cell, run again
    assert json.loads((out / "experiment.json").read_text())["warm_up"] is True
    assert "warm_up False -> True" in capsys.readouterr().err
    records = [json.loads(line) for line in (out / "results.jsonl").read_text().splitlines()]
    assert [r["status"] for r in records] == ["EXACT_SOLUTION"]  # PRM solves with its warm-up too
