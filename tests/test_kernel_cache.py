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
        assert isinstance(dispatcher._cache._cache_file, kernel_cache.LockedCacheFile), dispatcher


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


def _doubling_kernel_and_caller(jit: Any) -> tuple[Any, Any]:
    """A kernel made with ``jit``, and a caller that passes it a variable and two constants."""

    def twice(x: int) -> int:  # pragma: no cover (compiled)
        return 2 * x

    kernel = jit(twice)

    def call(x: int) -> int:  # pragma: no cover (compiled)
        return kernel(x) + kernel(3) + kernel(-1)

    return kernel, numba.njit(call)


@pytest.mark.parametrize("jit", [kernel_cache.njit, kernel_cache.njit_borrowing])
def test_a_kernel_called_with_constants_compiles_once_for_their_plain_type(jit: Any) -> None:
    # numba alone compiles the callee once for the variable and once for each constant ...
    plain_kernel, plain_caller = _doubling_kernel_and_caller(numba.njit)
    assert plain_caller(5) == 14
    assert len(plain_kernel.signatures) == 3
    # ... the package's kernels once: a constant is typed as the variable is
    kernel, caller = _doubling_kernel_and_caller(jit)
    assert caller(5) == 14
    assert [str(signature) for signature in kernel.signatures] == ["(int64,)"]


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


# One process's save or load of a package cache entry, started when the file ``go`` appears;
# numba's steps slowed down where a second process could come in between.
CACHE_ENTRY = """
import sys, time
from pathlib import Path
from numba.core import caching
from ompl_balance.core import kernel_cache

folder, action, key, value, go, stamp = sys.argv[1:7]
files = caching.IndexDataCacheFile  # (the class numba makes a cached function's files with)
slow_index, slow_data = files._save_index, files._save_data

def save_index(self, overloads):
    time.sleep(0.5)  # (between reading the index and writing it back)
    slow_index(self, overloads)
    Path(folder, "indexed").touch()

def save_data(self, name, data):
    time.sleep(1.0)  # (between writing the index and the data)
    slow_data(self, name, data)

files._save_index, files._save_data = save_index, save_data
source_stamp = ("source", kernel_cache.package_digest() if stamp == "package" else stamp)
cache = files(folder, "f", source_stamp)
while not Path(go).exists():
    time.sleep(0.005)
if action == "save":
    cache.save(key, value)
else:
    while not Path(folder, "indexed").exists():
        time.sleep(0.005)
    print(cache.load(key))
"""


def _cache_entry(folder: Path, action: str, key: str, value: str = "", stamp: str = "package") -> subprocess.Popen:
    go = folder / "go"
    command = [sys.executable, "-c", CACHE_ENTRY, str(folder), action, key, value, str(go), stamp]
    return subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def _finished(process: subprocess.Popen) -> str:
    stdout, stderr = process.communicate(timeout=120)
    assert process.returncode == 0, stderr
    return stdout.strip()


def _package_cache_file(folder: Path) -> Any:
    from numba.core import caching

    return caching.IndexDataCacheFile(str(folder), "f", ("source", kernel_cache.package_digest()))


def test_two_processes_saving_entries_of_one_function_at_once_keep_both(tmp_path) -> None:
    # (as the planning loop's specializations compiled in two processes: numba saves an entry by
    # reading the index, adding it under the first free data file name and writing it back)
    processes = [_cache_entry(tmp_path, "save", key, f"code of {key}") for key in ("a", "b")]
    (tmp_path / "go").touch()
    for process in processes:
        _finished(process)
    cache = _package_cache_file(tmp_path)
    assert [cache.load("a"), cache.load("b")] == ["code of a", "code of b"]


def test_a_load_during_a_save_never_reads_an_earlier_versions_data(tmp_path) -> None:
    # an earlier version of the package left its entry under the first data file name
    from numba.core import caching

    caching.IndexDataCacheFile(str(tmp_path), "f", ("source", "an earlier digest")).save("a", "old code of a")
    saving = _cache_entry(tmp_path, "save", "a", "code of a")
    loading = _cache_entry(tmp_path, "load", "a")  # (once the save has written its index)
    (tmp_path / "go").touch()
    _finished(saving)
    assert _finished(loading) == "code of a"


def test_a_cached_function_outside_the_package_is_not_locked(tmp_path) -> None:
    from numba.core import caching

    cache = caching.IndexDataCacheFile(str(tmp_path), "f", ("source", "not the package's digest"))
    cache.save("a", "code of a")
    assert cache.load("a") == "code of a"
    assert not list(tmp_path.glob("*.lock"))
    _package_cache_file(tmp_path).save("a", "code of a")
    assert [path.name for path in tmp_path.glob("*.lock")] == ["f.nbi.lock"]
