"""The ``viz`` extra: viser, imported only where a plan is shown, and the message without it."""

from __future__ import annotations

from types import ModuleType

from ..bench.errors import MissingExtraError

#: What installs the viewer.
INSTALL = "pip install 'ompl-balance[viz]'"


def require_viser() -> ModuleType:
    """The ``viser`` module; :class:`~ompl_balance.bench.errors.MissingExtraError` naming the extra
    when it is not installed."""
    try:
        import viser
    except ImportError as error:
        raise MissingExtraError(f"showing plans needs viser (the viz extra): {INSTALL}") from error
    return viser
