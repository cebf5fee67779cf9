"""The planning engine for each kind of check the tests plan with, made ready in a second process
while the tests run.

numba compiles the planning engine once per kind of check view, the first time after installing
(tens of seconds each, in a process of its own while the planning process waits: see
``ompl_balance.engine.loading``). pytest runs the tests one after another, so a first run would
wait for each kind in turn, minutes in all, with the machine's other core idle. :func:`start`
has a second process make each kind ready in the order the tests first need them; a test that
needs one while it compiles waits for it (the engine compiles a kind once at a time on the
machine, under a lock) rather than compiling it again, and later ones find it in numba's cache.
Where they are all compiled already, the process only loads them (seconds) and exits.

Run as a script, it is that process.
"""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

from ompl import base as ob
from ompl import geometric as og


def _square() -> og.SimpleSetup:
    space = ob.RealVectorStateSpace(2)
    space.setBounds(0.0, 1.0)
    return og.SimpleSetup(space)


def _python_callable() -> og.SimpleSetup:
    ss = _square()
    ss.setStateValidityChecker(lambda state: True)
    return ss


def _numba_function() -> og.SimpleSetup:
    import numba

    from ompl_balance import setup_checker

    ss = _square()
    setup_checker(ss, numba.njit(lambda q: q[0] >= 0.0))
    return ss


def _box_world() -> og.SimpleSetup:
    from ompl_balance import get_problem

    return get_problem("bug_trap").setup()


def _occupancy_grid() -> og.SimpleSetup:
    from ompl_balance.worlds.occupancy import rooms_problem

    return rooms_problem(se2=False).setup()


def _panda(motion: str) -> Callable[[], og.SimpleSetup]:
    def setup() -> og.SimpleSetup:
        from ompl_balance.collision.checker import CollisionChecker
        from ompl_balance.collision.robots import load_panda_vamp
        from ompl_balance.worlds.mbm import load_mbm

        robot = load_panda_vamp()
        problem = load_mbm("table_pick", robot.joint_names)[0]
        return problem.simple_setup(robot, CollisionChecker(robot, problem.environment), motion=motion)

    return setup


def _rigid_body(motion: str) -> Callable[[], og.SimpleSetup]:
    def setup() -> og.SimpleSetup:
        from ompl_balance import rigid_problem

        return rigid_problem("se2_slot").simple_setup(motion=motion)

    return setup


#: One problem per kind of check view the tests plan with on the compiled engine, in the order
#: the test files (run in alphabetical order) first need them.
KINDS: tuple[Callable[[], og.SimpleSetup], ...] = (
    _panda("certified"),
    _python_callable,
    _numba_function,
    _box_world,
    _occupancy_grid,
    _panda("discrete"),
    _rigid_body("certified"),
    _rigid_body("discrete"),
)


def make_ready(parent: int) -> None:
    """Make the compiled engine ready for each of :data:`KINDS` (compiled into numba's cache,
    or loaded from it), while process ``parent`` (the tests') runs."""
    from ompl_balance import BalancedRRTConnect
    from ompl_balance.engine.compiled import compile_in_this_process

    compile_in_this_process()  # (this process only compiles: no worker process needed)
    for make in KINDS:
        if os.getppid() != parent:  # (the tests ended without stopping this process: killed)
            return
        ss = make()
        planner = BalancedRRTConnect(ss.getSpaceInformation())
        planner.setEngine("compiled")
        ss.setPlanner(planner)
        ss.setup()  # (engine=compiled: waits for the engine)


def start() -> subprocess.Popen[bytes] | None:
    """Start :func:`make_ready` in a process of its own (niced, in a session of its own, output
    discarded) where the machine has more than one core; ``None`` where it has one."""
    if (os.cpu_count() or 1) < 2:
        return None
    import ompl_balance

    # the package the tests import, wherever that is
    package_parent = str(Path(ompl_balance.__file__).resolve().parents[1])
    path = os.pathsep.join(filter(None, (package_parent, os.environ.get("PYTHONPATH"))))
    return subprocess.Popen(
        [sys.executable, str(Path(__file__).resolve()), str(os.getpid())],
        env={**os.environ, "PYTHONPATH": path},
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,  # (stop() ends the engine's compiling processes with it)
    )


def stop(process: subprocess.Popen[bytes] | None) -> None:
    """End ``process`` and the processes it started, if still running (a compilation cut short
    leaves nothing behind in numba's cache: it writes an entry whole or not at all)."""
    if process is None or process.poll() is not None:
        return
    with contextlib.suppress(ProcessLookupError):  # (ended meanwhile)
        os.killpg(process.pid, signal.SIGKILL)
    process.wait()


if __name__ == "__main__":
    os.nice(5)  # (the tests' own process comes first)
    from ompl import util as ou

    ou.setLogLevel(ou.LOG_ERROR)
    make_ready(parent=int(sys.argv[1]))
