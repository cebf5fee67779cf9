"""Run a Python script in a fresh process, where OMPL's global seed can still be set."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def run_with_seed(script: str, seed: int) -> str:
    """The stripped standard output of ``python -c script seed`` run from the repository root."""
    result = subprocess.run(
        [sys.executable, "-c", script, str(seed)], capture_output=True, text=True, timeout=120, cwd=REPO, check=True
    )
    return result.stdout.strip()


def with_ctrl_c_as_in_a_terminal(command: list[str]) -> list[str]:
    """``command``, started with SIGINT's default action, as a terminal's foreground job has it
    (a test suite run as a background job passes "ignore" on, and Python then never raises
    KeyboardInterrupt): a Python stub resets it and replaces itself with ``command``."""
    stub = "import os, signal, sys; signal.signal(signal.SIGINT, signal.SIG_DFL); os.execv(sys.argv[1], sys.argv[1:])"
    return [sys.executable, "-c", stub, *command]
