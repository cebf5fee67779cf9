"""A line on standard error while numba compiles (once after installing), none when it loads from its cache."""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import pytest
from numba import njit

from ompl_balance.bench.compile_notice import compile_notice


def test_the_notice_speaks_when_numba_compiles_and_not_when_the_kernel_is_ready(capsys):
    @njit(cache=False)
    def doubled(x):
        return 2 * x

    @njit(cache=False)
    def tripled(x):
        return 3 * x

    with compile_notice("the test's kernel"):
        assert tripled(2) == 6  # compiled here, in a moment: not worth a line
    assert capsys.readouterr().err == ""
    with compile_notice("the test's kernel", quiet=0.0):
        assert doubled(21) == 42  # compiled here
        time.sleep(0.2)  # (the notice's timer runs in a thread)
    err = capsys.readouterr().err.splitlines()
    assert err[0] == "ompl-balance: compiling the test's kernel with numba, once after installing (a minute or so) ..."
    assert err[1].startswith("ompl-balance: the test's kernel compiled in ") and len(err) == 2
    with compile_notice("the test's kernel"):
        assert doubled(4) == 8  # compiled already
    assert capsys.readouterr().err == ""


@pytest.mark.slow
def test_the_first_sweep_after_installing_says_it_compiles_then_runs_every_run(tmp_path):
    """An empty numba cache stands for a fresh install: the robot kernels compile (about a minute
    on 2 cores), the forkserver says so, and then every run solves (none killed while compiling)."""
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "numba")}
    command = [str(Path(sys.executable).with_name("ompl-balance")), "compare", "--runs", "1"]
    done = subprocess.run(
        [*command, "--problems", "box.001", "-o", str(tmp_path / "out"), "--no-progress"],
        env=env,
        capture_output=True,
        text=True,
        timeout=900,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    assert "ompl-balance: compiling the robot layer's collision kernels with numba" in done.stderr
    assert "| 1 | 100% |" in done.stdout and "crashed" not in done.stdout
