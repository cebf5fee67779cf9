"""The RRT-Connect family's parameters, declared once: the planner's table and the compiled loop's settings.

:class:`RRTConnectSettings` is :class:`~ompl_balance.planners.BalancedRRTConnect`'s parameter
table (:mod:`ompl_balance.core.params` derives its ``ParamSet``, accessors, validation and
messages). :data:`LoopSettings`, the compiled loop's settings, is made from the same table: one
field per parameter but those of the solve around the loop (:data:`SOLVE_ONLY`), a policy as
its :class:`~ompl_balance.policies.SwapPolicy`, :class:`~ompl_balance.policies.NearestPolicy` or
:class:`~ompl_balance.policies.SamplePolicy` number, and the two things a solve works out
(:data:`DERIVED`). A new parameter of the loop is declared in the table, and read where the
loop uses it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, NamedTuple

from ..core.params import Settings, param
from ..policies import NEAREST_POLICIES, RENAMED_POLICIES, SAMPLE_POLICIES, SWAP_POLICIES

#: ``engine`` choices: the compiled engine where it applies (else Python), always compiled, always Python.
ENGINES = ("auto", "compiled", "python")


@dataclass
class RRTConnectSettings(Settings):
    """The parameters of :class:`~ompl_balance.planners.BalancedRRTConnect` (OMPL names; distances in the space's units)."""

    range: float = param(
        0.0,
        "longest motion added to a tree in one step; 0 picks 0.2 x the space's maximum extent at setup()",
        low=0.0,
        suggestion="0.:1.:10000.",
    )
    intermediate_states: bool = param(
        False,
        "add the states along each motion (at the validity-checking resolution) to the tree, "
        "as OMPL's RRTConnect with addIntermediateStates",
    )
    balance_tree_sizes: bool = param(
        True,
        "grow the smaller tree once |a - b| / min(a, b) reaches max_tree_size_ratio (a, b the tree sizes); "
        "otherwise swap_policy decides",
    )
    max_tree_size_ratio: float = param(
        1.0,
        "the balancing rule's ratio; 1.0 grows the smaller tree once it is less than half the size of the other",
        low=0.0,
        suggestion="0.:0.05:10.",
    )
    swap_policy: str = param(
        "alternate",
        "which tree grows when balancing does not decide: the other one each iteration (stock), "
        "the same one until swap_steps connect steps were taken (the swap limiter), or until a connect collides",
        choices=SWAP_POLICIES,
        renamed=RENAMED_POLICIES,
    )
    swap_steps: int = param(10, "connect steps after which swap_limit swaps trees", low=1, suggestion="1:1:100")
    nearest_policy: str = param(
        "euclidean",
        "the node a tree grows from: the nearest (the space's metric), the nearest not exhausted "
        "(exhausted_after), or the least distance x exhaustion scale (exhaustion_target)",
        choices=NEAREST_POLICIES,
    )
    exhausted_after: int = param(15, "failed extensions after which a node is exhausted", low=1, suggestion="1:1:100")
    exhaustion_target: int = param(
        5, "failures at which the exhaustion scale is lowest (0.9)", low=1, suggestion="1:1:100"
    )
    sample_policy: str = param(
        "uniform",
        "where each iteration's target comes from (see ompl_balance.policies.target_choice)",
        choices=SAMPLE_POLICIES,
    )
    goal_bias: float = param(
        0.05, "probability that goal_bias targets the other tree's root", low=0.0, high=1.0, suggestion="0.:.05:1."
    )
    uniform_rate: float = param(
        0.1,
        "probability that an iteration of goal_ball, neighbour_quality or valid_sampler targets a uniform sample "
        "of the whole space instead, which keeps those policies probabilistically complete; 0: their targets "
        "only (the strict rules)",
        low=0.0,
        high=1.0,
        suggestion="0.:.05:1.",
    )
    min_quality: float = param(
        0.0, "lowest acceptance probability of neighbour_quality", low=0.0, high=1.0, suggestion="0.:.05:1."
    )
    seed: int = param(
        0,
        "0: each solve draws its seed from an OMPL RNG (repeated by ompl.util.RNG.setSeed); > 0: every solve "
        "uses this seed (real-vector, SO(2), SO(3), SE(2), SE(3) spaces and their compounds; other spaces "
        "sample with OMPL's sampler and seed)",
        low=0,
        suggestion="0:1:1000000",
    )
    engine: str = param(
        "auto",
        "the loop's implementation: compiled (numba; the spaces seed names, every sample_policy but "
        "valid_sampler, the package's checkers called as compiled kernels), python (any space and policy), "
        "or auto: compiled where it applies and is loaded, else python (the same trees in real-vector spaces)",
        choices=ENGINES,
    )


#: Parameters the solve around the loop uses, not the loop itself.
SOLVE_ONLY = ("seed", "engine")
#: What a solve works out for the loop besides the parameters: whether a step of ``range`` can
#: round back onto its start (``Points.may_stall``), and whether the loop records what it does.
DERIVED = (("step_may_stall", bool), ("record", bool))

#: The loop's parameters: (name, the choices of a choice parameter or ``None``, the type of a number).
_LOOP_PARAMS = tuple(
    (row.name, row.domain.choices, row.domain.kind) for row in RRTConnectSettings.table() if row.name not in SOLVE_ONLY
)
_TYPES: dict[type, type] = {bool: bool, int: int, float: float, str: int}  # a choice: its number
if TYPE_CHECKING:  # (its fields come from the table: to the type checker, any settings)
    LoopSettings = Any
else:
    LoopSettings = NamedTuple("LoopSettings", [(name, _TYPES[kind]) for name, _, kind in _LOOP_PARAMS] + list(DERIVED))
    LoopSettings.__doc__ = "The compiled loop's settings (see the module docstring), made from RRTConnectSettings."


def loop_settings(settings: RRTConnectSettings, step_may_stall: bool, record: bool) -> LoopSettings:
    """The compiled loop's :data:`LoopSettings` for a planner's ``settings`` (a choice as its number)."""
    values: dict[str, Any] = {"step_may_stall": bool(step_may_stall), "record": bool(record)}
    for name, choices, kind in _LOOP_PARAMS:
        value = getattr(settings, name)
        values[name] = choices.index(value) if choices is not None else kind(value)
    return LoopSettings(**values)
