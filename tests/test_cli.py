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
    assert all("| 1.00 | 1.00 | 1.00 |" in row for row in stock_rows)  # stock is the baseline
    assert all("| 2 | 100% |" in row for row in rows)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["compare", "--runs", "0"], "must be a whole number >= 1"),
        (["compare", "--time-limit", "-1"], "positive number of seconds"),
        (["compare", "--problems", "open,nowhere"], "unknown problem(s) nowhere"),
    ],
)
def test_bad_options_are_refused_with_a_reason(args, message, capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(args)
    assert exit_info.value.code == 2
    assert message in capsys.readouterr().err
