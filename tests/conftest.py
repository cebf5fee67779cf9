"""Test session settings."""

import atexit
import os
import shutil
import tempfile

import pytest

# The tests compute what the package caches on disk (covering spheres, certified-free
# tables) afresh, in a cache of their own, rather than reading a user's cache: a change
# to those computations must be tested, not served from an earlier version's files.
# It is removed when the test session's process exits.
os.environ["OMPL_BALANCE_CACHE"] = tempfile.mkdtemp(prefix="ompl_balance_test_cache_")
atexit.register(shutil.rmtree, os.environ["OMPL_BALANCE_CACHE"], ignore_errors=True)


def pytest_sessionstart(session):
    """Have the planning engine's kinds of check compiled by a second process while the tests
    run (the first run after installing; see ``compile_ahead``)."""
    import compile_ahead

    session.config.stash[_COMPILING] = compile_ahead.start()


def pytest_sessionfinish(session, exitstatus):
    import compile_ahead

    compile_ahead.stop(session.config.stash.get(_COMPILING, None))


_COMPILING = pytest.StashKey()
