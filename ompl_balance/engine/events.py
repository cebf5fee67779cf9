"""What both engines of the loop report: step outcomes, the loop's counts, and its record.

A :class:`LoopRecord` given to a planner (``planner.loop_record = LoopRecord()``) receives,
in order, every tree choice and every extension and connect step of the solves that follow,
from either engine: the public way to observe the loop (tests and teaching use it).
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from ..policies import SwapCause


class Grow(enum.IntEnum):
    """Outcome of one extension step, as OMPL's ``RRTConnect::GrowState``."""

    TRAPPED = 0  # no progress: the motion was invalid
    ADVANCED = 1  # a step of length ``range`` towards the target was added
    REACHED = 2  # the target itself was added


class TreeChoiceEvent(NamedTuple):
    """An iteration's tree choice: what the rule was given and what it chose."""

    iteration: int  # 1-based, in the solve
    grew_start: bool  # the tree the previous iteration grew
    steps: int  # connect steps since the last swap, as given to the rule
    collided: bool  # the last connect ended trapped, as given to the rule
    grow_start: bool  # the tree this iteration grows
    cause: SwapCause | None  # why, if it is a swap


class GrowStep(NamedTuple):
    """One extension step (``connect`` False: the iteration's extension; True: a connect step)."""

    iteration: int
    start_tree: bool  # the tree grown is the start tree
    connect: bool
    target: np.ndarray  # (dim,) the step's target
    node: int  # the node extended
    node_given: bool  # the node was handed over (a connect's further steps, neighbour quality), not looked up
    outcome: Grow
    added: int  # the node added (-1 when trapped; the last one with intermediate states)


@dataclass
class LoopRecord:
    """Tree choices and steps, in the order the loop made them (see the module docstring)."""

    choices: list[TreeChoiceEvent] = field(default_factory=list)
    steps: list[GrowStep] = field(default_factory=list)


@dataclass
class LoopCounts:
    """What one solve's loop counted, for ``RunStats``."""

    iterations: int = 0
    swaps: list[int] = field(default_factory=lambda: [0] * len(SwapCause))  # by SwapCause
    exits: int = 0  # calls out of compiled code to Python (compiled engine)
