"""The ompl-balance command line: compare runs and prints the table; bad options are refused."""

import pytest

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
        (["compare", "--problems", "open,nowhere"], "unknown problem(s) nowhere"),
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
