"""numba's disk cache of the package's kernels: renewed when any of the package's source changes."""

from __future__ import annotations

import importlib
import subprocess
import sys
from pathlib import Path
from typing import Any

import numba
import numpy as np
import pytest
from numba.core.caching import FunctionCache
from numba.core.dispatcher import Dispatcher
from numba.core.errors import TypingError

import ompl_balance
from ompl_balance.core import kernel_cache
from ompl_balance.core.kernel_cache import PackageCacheLocator

# A caller in one module, its callee in another, both cached; the callee is then edited.
CALLEE = """
from ompl_balance.core.kernel_cache import njit

@njit(cache=True)
def g(x):
    return x + {step}
"""
CALLER = """
from ompl_balance.core.kernel_cache import njit
from callee import g

@njit(cache=True)
def f(x):
    return 10 * g(x)
"""
RUN = """
import sys
from pathlib import Path
from ompl_balance.core import kernel_cache
kernel_cache.PACKAGE = Path(sys.argv[1]).resolve()  # the functions below count as the package's
sys.path.insert(0, sys.argv[1])
from caller import f
print(f(1))
"""


def _run(folder: Path) -> int:
    done = subprocess.run(
        [sys.executable, "-c", RUN, str(folder)], capture_output=True, text=True, check=True, timeout=300
    )
    return int(done.stdout.strip())


def test_an_edited_callee_is_compiled_again_in_its_callers(tmp_path) -> None:
    (tmp_path / "caller.py").write_text(CALLER)
    (tmp_path / "callee.py").write_text(CALLEE.format(step=1))
    assert _run(tmp_path) == 20
    assert list((tmp_path / "__pycache__").glob("caller.f-*.nbi")), "the caller was not cached"
    (tmp_path / "callee.py").write_text(CALLEE.format(step=2))
    # numba's own locator keys the caller by caller.py alone and would run the old g inside it (20)
    assert _run(tmp_path) == 30


def test_the_digest_follows_every_source_file(tmp_path, monkeypatch) -> None:
    (tmp_path / "sub").mkdir()
    (tmp_path / "a.py").write_text("x = 1\n")
    (tmp_path / "sub" / "b.py").write_text("y = 2\n")
    monkeypatch.setattr(kernel_cache, "PACKAGE", tmp_path)
    kernel_cache.package_digest.cache_clear()
    try:
        first = kernel_cache.package_digest()
        (tmp_path / "sub" / "b.py").write_text("y = 3\n")
        kernel_cache.package_digest.cache_clear()
        assert kernel_cache.package_digest() != first
        (tmp_path / "sub" / "b.py").write_text("y = 2\n")
        kernel_cache.package_digest.cache_clear()
        assert kernel_cache.package_digest() == first
    finally:
        kernel_cache.package_digest.cache_clear()


def test_every_cached_kernel_of_the_package_uses_the_package_locator() -> None:
    root = Path(ompl_balance.__file__).parent
    sources = {path: path.read_text() for path in root.rglob("*.py") if path.name != "kernel_cache.py"}
    # no module takes numba's njit directly (its functions would keep numba's locator)
    assert [path.relative_to(root).as_posix() for path, text in sources.items() if _imports_njit(text)] == []
    cached = []
    for path, text in sources.items():
        if "cache=True" in text:
            name = ".".join(("ompl_balance", *path.relative_to(root).with_suffix("").parts))
            module = importlib.import_module(name)
            cached += [
                value
                for value in vars(module).values()
                if isinstance(value, Dispatcher) and isinstance(value._cache, FunctionCache)
            ]
    assert len(cached) > 50
    for dispatcher in cached:
        assert isinstance(dispatcher._cache._impl.locator, PackageCacheLocator), dispatcher


def _imports_njit(text: str) -> bool:
    return any(
        line.startswith("from numba import")
        and "njit" in [name.strip() for name in line.split(" import ")[1].split(",")]
        for line in text.splitlines()
    )


def test_a_function_outside_the_package_keeps_numbas_locator(tmp_path) -> None:
    source = tmp_path / "outside.py"
    source.write_text("def h(x):\n    return x\n")
    assert PackageCacheLocator.from_function(lambda x: x, str(source)) is None


@kernel_cache.njit_borrowing
def _borrowed_sum(values: np.ndarray) -> float:  # pragma: no cover (compiled)
    total = 0.0
    for value in values:
        total += value
    return total


@kernel_cache.njit_borrowing
def _allocates(count: int) -> float:  # pragma: no cover (compiled)
    return float(np.zeros(count).sum())


def test_a_borrowing_kernel_reads_its_callers_arrays_and_refuses_to_allocate():
    values = np.arange(5.0)
    assert _borrowed_sum(values) == 10.0
    assert values.tolist() == [0.0, 1.0, 2.0, 3.0, 4.0]
    with pytest.raises(TypingError):
        _allocates(3)


def _allocating_kernel_and_borrowing_caller(jit: Any) -> tuple[Any, Any]:
    """A kernel made with ``jit`` that allocates, and a borrowing caller of it: neither compiled
    yet, nor cached (each run compiles the kernel from its caller, as a fresh install does)."""

    def allocate(count: int) -> float:  # pragma: no cover (compiled)
        return float(np.ones(count).sum())

    kernel = jit(allocate)

    def call(count: int) -> float:  # pragma: no cover (compiled)
        return kernel(count)

    borrowing: dict[str, Any] = {"_nrt": False}  # (njit_borrowing's setting, without its cache)
    return kernel, numba.njit(**borrowing)(call)


def test_a_package_kernel_that_allocates_compiles_when_a_borrowing_kernel_calls_it_first():
    # numba compiles a callee with its caller's reference counting unless the callee states its
    # own: a plain numba kernel first called from a borrowing one cannot allocate ...
    _, caller = _allocating_kernel_and_borrowing_caller(numba.njit)
    with pytest.raises(TypingError):
        caller(3)
    # ... the package's njit states it, so the planning loop may be the first to call any kernel
    kernel, caller = _allocating_kernel_and_borrowing_caller(kernel_cache.njit)
    assert not kernel.overloads
    assert caller(4) == 4.0
