"""The ompl-balance command line: compare runs and prints the table; bad options, missing extras
and wrong folders end in one line saying what to do."""

import json
import sys

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
    ],
)
def test_bad_options_are_refused_with_a_reason(args, message, capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(args)
    assert exit_info.value.code == 2
    assert message in capsys.readouterr().err


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


def test_plot_without_matplotlib_is_one_line_naming_the_install(monkeypatch, capsys, tmp_path):
    (tmp_path / "experiment.json").write_text(json.dumps(compare_experiment(["open"], runs=1).as_dict()))
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    _one_line_error(capsys, ["plot", str(tmp_path)], "pip install 'ompl-balance[plot]'")


def test_plot_of_a_folder_that_is_not_an_output_folder_is_one_line(capsys, tmp_path):
    _one_line_error(capsys, ["plot", str(tmp_path / "nowhere")], "is not an output folder (no experiment.json)")
    (tmp_path / "experiment.json").write_text("{not json")
    _one_line_error(capsys, ["plot", str(tmp_path)], "cannot be read as an experiment")
