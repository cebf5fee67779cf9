"""``ompl-balance show``: plan a problem given by name, then show it (live, or written to a file)."""

from __future__ import annotations

import contextlib
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from ompl import util as ou

from .extra import require_viser
from .live import LiveViewer
from .page import Page, write_page
from .plan import Plan, animation_frames, path_states, planner_trees
from .problems import Named, named_problem

#: The planner ``show`` plans with unless told otherwise.
DEFAULT_PLANNER = "BalancedRRTConnect"
#: Seconds of planning when neither the user nor the problem says.
DEFAULT_TIME_LIMIT = 10.0
#: Frames of the path's animation.
FRAMES = 150

_SOLVED = ("Exact solution", "Approximate solution")


@dataclass
class Planned:
    """A named problem planned: the ``problem``, the ``plan`` to show, the animation's ``frames``,
    whether a path was found, and the seconds planning took."""

    problem: Named
    plan: Plan
    solved: bool
    seconds: float

    @property
    def frames(self) -> np.ndarray:
        """The animation's states (m, state size); without a path, the start alone."""
        frames = animation_frames(self.problem.scene, self.plan.path, FRAMES)
        return frames if len(frames) else self.problem.start[None]


def plan_named(
    name: str,
    planner: str = DEFAULT_PLANNER,
    seed: int | None = None,
    time_limit: float | None = None,
    trees: bool = False,
    end_effector: str | None = None,
) -> Planned:
    """Plan problem ``name`` (:func:`~ompl_balance.viz.problems.named_problem`) with ``planner``
    (``NAME`` or ``NAME[param=value;...]``: a stock OMPL planner or one of the package's).

    ``seed`` seeds OMPL's random numbers (before the first is drawn in this process);
    ``time_limit`` (s) defaults to the problem's suggestion, else :data:`DEFAULT_TIME_LIMIT`.
    ``ValueError`` for an unknown problem or planner, or a bad parameter.
    """
    from ..bench.compare import parse_planners
    from ..bench.errors import ExperimentError

    if seed is not None:  # first: a planner made below draws from OMPL's seed
        ou.RNG.setSeed(seed)
    specs = parse_planners(planner)
    if len(specs) != 1:
        raise ValueError(f"show plans with one planner, got {len(specs)}: {planner!r}")
    try:
        specs[0].check()
    except ExperimentError as error:
        raise ValueError(f"planner {planner!r}: {error}") from None
    problem = named_problem(name, end_effector)
    scene = problem.scene
    ss = problem.setup()
    si = ss.getSpaceInformation()
    chosen = specs[0].build(si)
    ss.setPlanner(chosen)
    limit = time_limit if time_limit is not None else problem.time_limit or DEFAULT_TIME_LIMIT
    began = time.perf_counter()
    status = ss.solve(limit)
    seconds = time.perf_counter() - began
    words = str(status.asString() if hasattr(status, "asString") else status)
    solved = words in _SOLVED and ss.haveSolutionPath()
    path = path_states(scene, ss.getSolutionPath()) if solved else np.zeros((0, scene.state_size))
    goal = path[-1] if len(path) else problem.goal
    found = planner_trees(si, chosen, scene) if trees else []
    plan = Plan(problem.start, goal, path, found, words, specs[0].label)
    return Planned(problem, plan, solved, seconds)


def run_show(
    name: str,
    file: Path | None = None,
    planner: str = DEFAULT_PLANNER,
    seed: int | None = None,
    time_limit: float | None = None,
    trees: bool = False,
    host: str = "127.0.0.1",
    port: int = 8080,
    open_browser: bool = True,
    end_effector: str | None = None,
) -> int:
    """The ``show`` command: plan, report, show; 0 when a path was found, 1 when not (the problem
    is shown either way, with what makes the start or goal invalid named and painted)."""
    require_viser()
    planned = plan_named(name, planner, seed, time_limit, trees, end_effector)
    plan, scene = planned.plan, planned.problem.scene
    print(f"{scene.title}: {plan.planner} {plan.status.lower()} in {planned.seconds:.2f} s", end="")
    print(f", {len(plan.path)} states" if planned.solved else "")
    for label, state in (("start", plan.start), ("goal", plan.goal)):
        problem = scene.problem(state) if state is not None else ""
        if problem:
            print(f"the {label} state is not valid: {problem}", file=sys.stderr)
    for note in scene.notes:
        print(note)
    if file is not None:
        began = time.perf_counter()
        page: Page = write_page(scene, plan, planned.frames, file, trees)
        size = page.path.stat().st_size
        print(f"wrote {page.path} ({size / 1e6:.1f} MB, {time.perf_counter() - began:.1f} s): open it in a browser")
    else:
        viewer = LiveViewer(scene, plan, planned.frames, trees, host, port)
        with contextlib.suppress(KeyboardInterrupt):  # (one before the wait: the viewer stopped all the same)
            viewer.present(open_browser)
        print("viewer stopped")
    return 0 if planned.solved else 1
