"""numba's disk cache of the package's kernels, renewed whenever any of the package's source changes.

numba keys a cached function by the source of its own file only. A kernel compiles in the
kernels it calls from other modules (the certified edge calls GJK, the planning loop calls
the checkers' kernels), so when only a callee's module changes, as after a ``git pull`` in a
checkout installed in place, numba would load the caller's old machine code and run the old
callee inside it, silently. Here every function defined in the package's files is cached
with its file's stamp *and* a digest of all the package's Python sources: any change to the
package compiles its kernels again (once, a minute or two), and no stale kernel ever runs.

The package compiles kernels in parallel processes (specializations of one function, the planning
loop, among them), which numba's cache does not guard against: the package's cache entries are
saved and loaded under a lock the machine's processes share (:class:`LockedCacheFile`).

The package's kernel modules take :func:`njit` from here rather than from numba: importing this
module puts :class:`PackageCacheLocator` first among numba's cache locators before any of them
is decorated (numba picks a function's locator when it is decorated).
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar, cast

import numba
from numba.core import caching, types
from numba.core.registry import CPUDispatcher

from .file_lock import file_lock

__all__ = [
    "LockedCacheFile",
    "PackageCacheLocator",
    "PlainTypedDispatcher",
    "cache_folder",
    "njit",
    "njit_borrowing",
    "package_digest",
]

_Kernel = TypeVar("_Kernel", bound=Callable[..., Any])


def njit(*args: Any, **options: Any) -> Any:
    """numba's ``njit``, with numba's reference counting stated rather than left to inherit, and
    calls from compiled code typed plainly (:class:`PlainTypedDispatcher`).

    numba compiles a kernel the first time compiled code calls it with the caller's setting of
    reference counting unless the kernel states its own; a kernel that allocates, first called
    from a borrowing one (:func:`njit_borrowing`, as the planning loop is), would then fail to
    compile, or compile, depending on which was compiled first in the process.
    """
    options.setdefault("_nrt", True)  # (numba's option for it, undeclared in its stubs)
    made = numba.njit(*args, **options)
    if isinstance(made, CPUDispatcher):
        return _plainly_typed(made)
    return lambda function: _plainly_typed(made(function))


def njit_borrowing(function: _Kernel) -> _Kernel:
    """``njit(cache=True)`` without numba's reference counting, for kernels that only borrow
    their caller's arrays: they neither allocate nor return arrays (numba refuses to compile
    either there).

    Each call of an ordinary kernel counts every array its arguments hold in and out, an
    atomic increment and decrement, some 17 ns an array: a nearest-node query that passed the
    space's layout and a tree (25 arrays) through three calls cost 1.6 us on a tree of 8 nodes,
    against 26 ns for the scan itself.
    """
    return cast(_Kernel, njit(cache=True, _nrt=False)(function))


class PlainTypedDispatcher(CPUDispatcher):
    """numba's dispatcher of a kernel, compiling a call from compiled code for its arguments' plain
    types.

    numba types a constant argument as a literal (``_note(loop, 0, -1)`` passes
    ``Literal[int](0)``) and compiles the callee once more for each such constant: the package's
    kernels were compiled up to four times over for constants alone (the rigid bodies' edge
    kernel twice, 6 s), all of it paid at first use. Typed plainly, one compilation serves every
    caller; LLVM still sees the constant where the call is inlined.
    """

    def get_call_template(self, args: Any, kws: Any) -> Any:
        plain_args = tuple(types.unliteral(arg) for arg in args)
        plain_kws = {name: types.unliteral(arg) for name, arg in kws.items()}
        return super().get_call_template(plain_args, plain_kws)


def _plainly_typed(dispatcher: Any) -> Any:
    dispatcher.__class__ = PlainTypedDispatcher  # (the same dispatcher, one method more specific)
    return dispatcher


#: The package's folder: functions defined in files below it are cached by :class:`PackageCacheLocator`.
PACKAGE = Path(__file__).resolve().parents[1]


@functools.lru_cache(maxsize=1)
def package_digest() -> str:
    """SHA-256 of the package's Python sources (their paths and contents), worked out once a process."""
    digest = hashlib.sha256()
    for path in sorted(PACKAGE.rglob("*.py")):
        digest.update(path.relative_to(PACKAGE).as_posix().encode())
        digest.update(b"\0")
        digest.update(path.read_bytes())
        digest.update(b"\0")
    return digest.hexdigest()


def cache_folder() -> Path | None:
    """The folder where numba keeps the cached kernels of this module's folder (``core``'s, in the
    package's tree, under ``NUMBA_CACHE_DIR`` or in the user's cache, as numba decides); ``None``
    where numba can keep none. What is kept there goes when the cache does (a reinstall)."""
    locator = PackageCacheLocator.from_function(cache_folder, __file__)
    return None if locator is None else Path(locator.get_cache_path())


def _in_package(py_file: str) -> bool:
    try:
        Path(py_file).resolve().relative_to(PACKAGE)
    except (OSError, ValueError):
        return False
    return True


class PackageCacheLocator(caching._CacheLocator):
    """numba's own locator for a function defined in the package (where and under which name its
    cache lives), with :func:`package_digest` added to the source stamp that decides whether a
    cached entry is still good."""

    def __init__(self, inner: Any) -> None:
        self._inner = inner
        self._py_file = getattr(inner, "_py_file", "")  # (numba's warnings read it)

    def ensure_cache_path(self) -> None:
        self._inner.ensure_cache_path()

    def get_cache_path(self) -> str:
        return str(self._inner.get_cache_path())

    def get_source_stamp(self) -> Any:
        return (self._inner.get_source_stamp(), package_digest())

    def get_disambiguator(self) -> str:
        return str(self._inner.get_disambiguator())

    @classmethod
    def from_function(cls, py_func: Any, py_file: str) -> PackageCacheLocator | None:
        if not _in_package(py_file):
            return None
        for locator_class in _NUMBAS_LOCATORS:
            inner = locator_class.from_function(py_func, py_file)
            if inner is not None:
                return cls(inner)
        return None


# numba's locators, in its order of preference (``CacheImpl``; ``_CacheImpl`` in older numba)
_LOCATORS: list[Any] = (getattr(caching, "CacheImpl", None) or getattr(caching, "_CacheImpl"))._locator_classes  # noqa: B009
_NUMBAS_LOCATORS = [locator for locator in _LOCATORS if locator is not PackageCacheLocator]
if PackageCacheLocator not in _LOCATORS:
    _LOCATORS.insert(0, PackageCacheLocator)


class LockedCacheFile(caching.IndexDataCacheFile):
    """numba's index and data files of a cached function; for the package's functions (their source
    stamp is :class:`PackageCacheLocator`'s), saved and loaded under a lock beside the index.

    numba saves an entry by reading the function's index, adding the entry under the first data
    file name the index does not use, writing the index back, then the data; it loads by reading
    the index, then the named data file, and does not check that the data is the entry's. So two
    processes saving specializations of one function at once could keep one entry of the two and
    write both compiled codes to one file, and a load between a save's index and its data could
    read a data file of that name left by an earlier version of the package: the wrong machine
    code for the arguments. Under the lock a save is whole before another save or a load starts
    (loads share it: they only read).
    """

    def __init__(self, cache_path: str, filename_base: str, source_stamp: Any) -> None:
        super().__init__(cache_path, filename_base, source_stamp)
        package = isinstance(source_stamp, tuple) and len(source_stamp) == 2 and source_stamp[1] == package_digest()
        self._lock_path = f"{self._index_path}.lock" if package else None

    def save(self, key: Any, data: Any) -> None:
        with self._locked(shared=False):
            super().save(key, data)

    def load(self, key: Any) -> Any:
        with self._locked(shared=True):
            return super().load(key)

    def _locked(self, shared: bool) -> contextlib.AbstractContextManager[None]:
        return contextlib.nullcontext() if self._lock_path is None else file_lock(self._lock_path, shared)


# numba makes a cached function's files when the function is decorated, with the class of this name
caching.IndexDataCacheFile = LockedCacheFile  # type: ignore[misc]
