"""The examples answer --help without running, say in one line which extra they need, and print their
results without OMPL's log lines."""

from __future__ import annotations

import subprocess
import sys
from importlib import metadata
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
SCRIPTS = sorted(path.name for path in EXAMPLES.glob("*.py"))

#: Runs an example with one module or distribution made unavailable, as without its extra.
WITHOUT = """\
import runpy, sys
from importlib import metadata
missing, script = sys.argv[1], sys.argv[2]
sys.modules[missing] = None  # import fails as if not installed
distribution = metadata.distribution
def without(name):
    if name == missing:
        raise metadata.PackageNotFoundError(name)
    return distribution(name)
metadata.distribution = without
sys.argv = sys.argv[2:]
runpy.run_path(script, run_name="__main__")
"""


def test_every_example_is_covered():
    assert SCRIPTS == [
        "balanced_rrtc_2d.py",
        "ball_radius_constant.py",
        "panda_table.py",
        "rigid_body.py",
        "variants_2d.py",
    ]


@pytest.mark.parametrize("script", SCRIPTS)
def test_help_prints_usage_and_plans_nothing(script):
    done = subprocess.run(
        [sys.executable, str(EXAMPLES / script), "--help"], capture_output=True, text=True, timeout=120, check=False
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("usage: ")
    # what each example prints once it plans
    assert not any(text in done.stdout for text in ("status:", " queries ", "certified ", "figures written"))


@pytest.mark.parametrize(
    ("script", "missing", "install", "arguments"),
    [
        ("ball_radius_constant.py", "matplotlib", "pip install 'ompl-balance[plot]'", ["OUT"]),
        ("panda_table.py", "example-robot-data", "pip install 'ompl-balance[robots]'", []),
    ],
)
def test_an_example_without_its_extra_says_which_in_one_line(script, missing, install, arguments, tmp_path):
    done = subprocess.run(
        [sys.executable, "-c", WITHOUT, missing, str(EXAMPLES / script), *arguments],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert done.returncode != 0
    assert install in done.stderr and "Traceback" not in done.stderr, done.stderr
    assert len(done.stderr.strip().splitlines()) == 1, done.stderr


def test_panda_table_prints_its_results_without_ompls_log_lines():
    try:
        metadata.distribution("example-robot-data")
    except metadata.PackageNotFoundError:
        pytest.skip("example-robot-data is not installed (the robots extra)")
    done = subprocess.run(
        [sys.executable, str(EXAMPLES / "panda_table.py"), "--time-limit", "2"],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert [line.split()[0] for line in lines] == ["RRTConnect", "BalancedRRTConnect"], done.stdout
    assert not any(
        ("Debug:" in line or "Info:" in line) for line in done.stdout.splitlines() + done.stderr.splitlines()
    )
