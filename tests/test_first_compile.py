"""The first sweep after installing: the forkserver's modules compiled in parallel processes, once;
the first test run: the engine's kinds of check compiled ahead of the tests that need them."""

from __future__ import annotations

import os
import time
from pathlib import Path

import compile_ahead
import numpy as np
import pytest

import ompl_balance
from ompl_balance.bench import first_compile
from ompl_balance.core import kernel_cache
from ompl_balance.core.discrete_motion_kernels import bisection_order
from ompl_balance.core.layout import layout_for
from ompl_balance.engine.loading import view_key
from ompl_balance.engine.views import checks_for

# a module standing for a preload module: it notes when it was imported and takes a while,
# as numba compiling would
SLOW_MODULE = """
import os, pathlib, time
began = time.time()
time.sleep(SECONDS)
pathlib.Path(os.environ["IMPORTS"], __name__).write_text(f"{began} {time.time()}")
print("Info: what OMPL prints on standard output")
"""


@pytest.fixture
def slow_modules(tmp_path, monkeypatch):
    modules = tmp_path / "modules"
    modules.mkdir()
    for name, seconds in (("slow_one", 1.0), ("slow_two", 1.0), ("short", 0.3), ("long", 4.0)):
        (modules / f"{name}.py").write_text(SLOW_MODULE.replace("SECONDS", str(seconds)))
    (tmp_path / "imports").mkdir()
    package_parent = str(Path(ompl_balance.__file__).resolve().parents[1])  # (the package the tests import)
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join((str(modules), package_parent)))
    monkeypatch.setenv("IMPORTS", str(tmp_path / "imports"))
    monkeypatch.setattr(kernel_cache, "cache_folder", lambda: tmp_path)  # where the done markers go
    monkeypatch.setattr(first_compile.os, "cpu_count", lambda: 2)
    return tmp_path / "imports"


def test_modules_are_imported_at_once_in_processes_of_their_own_then_never_again(slow_modules, capfd):
    began = time.time()
    first_compile.compile_in_parallel(["__main__", "slow_one", "slow_two"])
    spans = [tuple(map(float, (slow_modules / name).read_text().split())) for name in ("slow_one", "slow_two")]
    assert max(start for start, _ in spans) < min(end for _, end in spans)  # they overlapped
    assert all(began <= start for start, _ in spans)
    assert "Info:" not in capfd.readouterr().out  # the tables' stream stays clean
    for path in slow_modules.iterdir():
        path.unlink()
    first_compile.compile_in_parallel(["__main__", "slow_one", "slow_two"])
    assert list(slow_modules.iterdir()) == []  # done once: not imported again


def test_a_single_module_is_left_to_the_forkserver(slow_modules):
    first_compile.compile_in_parallel(["__main__", "slow_one"])
    assert list(slow_modules.iterdir()) == []


def test_modules_start_in_order_and_the_next_as_soon_as_any_ends(slow_modules):
    first_compile.compile_in_parallel(["__main__", "long", "short", "slow_one"])
    spans = {
        name: tuple(map(float, (slow_modules / name).read_text().split())) for name in ("slow_one", "long", "short")
    }
    assert spans["long"][0] < spans["slow_one"][0] and spans["short"][0] < spans["slow_one"][0]
    # slow_one takes the core short leaves, while long (started first) still runs
    assert spans["short"][1] <= spans["slow_one"][0] < spans["long"][1]


def test_the_note_that_a_module_compiled_is_kept_where_numba_caches_the_packages_kernels():
    # a reinstall in the same place empties numba's cache: a note kept elsewhere (the temporary
    # folder) would outlive it and the next first run would compile on one core
    bisection_order(4, np.zeros((4, 2), dtype=np.int64), np.zeros(4, dtype=np.int64))  # cached, or compiled
    folder = first_compile._done_marker("some_module").parent
    assert any(folder.glob("discrete_motion_kernels.bisection_order-*.nbi"))  # numba's own index of it


def test_the_suite_compiles_each_kind_of_check_ahead_once():
    keys = []
    for make in compile_ahead.KINDS:
        si = make().getSpaceInformation()
        si.setup()
        layout = layout_for(si.getStateSpace())
        keys.append(view_key((checks_for(si, layout).view, layout)))
    assert len(set(keys)) == len(keys)  # each a kind of its own: one compilation of the engine each


def test_compiling_ahead_ends_with_the_session_and_leaves_no_process():
    if not Path("/proc/self/stat").is_file():
        pytest.skip("no /proc to list processes by group")
    process = compile_ahead.start()
    if process is None:
        pytest.skip("one core: nothing is compiled ahead")
    time.sleep(2.0)  # (under way: importing, or an engine compiling in a process it started)
    compile_ahead.stop(process)
    assert process.returncode is not None
    # nor any process it started (its session's group), once the system has reaped them
    deadline = time.monotonic() + 30.0
    while _group_alive(process.pid) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not _group_alive(process.pid)


def _group_alive(group: int) -> bool:
    """Whether a process of process group ``group`` runs (a zombie, dead but not yet reaped, does not)."""
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rpartition(")")[2].split()  # (after the command's name)
        except OSError:  # (ended meanwhile)
            continue
        if int(fields[2]) == group and fields[0] != "Z":
            return True
    return False


def test_a_process_that_only_compiles_compiles_the_engine_itself(monkeypatch):
    # a process that plans has a missing engine compiled by a worker process (its interpreter
    # stays free); one that only compiles does it in itself, without a worker's start-up
    from ompl_balance.core import compiled_calls
    from ompl_balance.engine import compiled

    si = compile_ahead.KINDS[3]().getSpaceInformation()  # the box world
    si.setup()
    layout = layout_for(si.getStateSpace())
    view = checks_for(si, layout).view
    workers = []
    monkeypatch.setattr(compiled_calls, "load_cached", lambda kernel, arguments: False)  # (as if not cached)
    monkeypatch.setattr(compiled.subprocess, "run", lambda command, **options: workers.append(command))
    compiled._warm(view, layout)
    assert len(workers) == 1 and workers[0][-1] == "ompl_balance.engine.compile_worker"
    monkeypatch.setattr(compiled._Compiling, "in_this_process", False)
    compiled.compile_in_this_process()
    compiled._warm(view, layout)  # (loaded from numba's cache here: the warm-up finds it there)
    assert len(workers) == 1
