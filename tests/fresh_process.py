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
