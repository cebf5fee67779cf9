"""The disk cache returns what was computed, and never stands in the way."""

import numpy as np
from test_validity import arm3_scene

from ompl_balance.collision.cache import cache_dir, cached_arrays
from ompl_balance.collision.checker import CollisionChecker


def counting(calls: list):
    def compute():
        calls.append(1)
        return {"a": np.arange(5.0) / 3.0, "b": np.array([[True, False]])}

    return compute


def test_second_call_reads_what_the_first_computed(tmp_path, monkeypatch):
    monkeypatch.setenv("OMPL_BALANCE_CACHE", str(tmp_path))
    calls = []
    first = cached_arrays("thing", ["x", np.ones(3)], counting(calls))
    second = cached_arrays("thing", ["x", np.ones(3)], counting(calls))
    assert len(calls) == 1 and len(list(tmp_path.glob("thing-*.npz"))) == 1
    for name in first:
        np.testing.assert_array_equal(first[name], second[name])
        assert first[name].dtype == second[name].dtype
    cached_arrays("thing", ["x", np.ones(4)], counting(calls))  # another key: computed
    assert len(calls) == 2


def test_damaged_file_is_computed_again(tmp_path, monkeypatch):
    monkeypatch.setenv("OMPL_BALANCE_CACHE", str(tmp_path))
    calls = []
    cached_arrays("thing", [1], counting(calls))
    (file,) = tmp_path.glob("thing-*.npz")
    file.write_bytes(b"not an npz")
    again = cached_arrays("thing", [1], counting(calls))
    assert len(calls) == 2 and again["a"][1] == 1 / 3


def test_off_and_unwritable(tmp_path, monkeypatch):
    monkeypatch.setenv("OMPL_BALANCE_CACHE", "")
    assert cache_dir() is None
    calls = []
    cached_arrays("thing", [1], counting(calls))
    cached_arrays("thing", [1], counting(calls))
    assert len(calls) == 2
    blocker = tmp_path / "file"
    blocker.write_text("a file where the cache directory would go")
    monkeypatch.setenv("OMPL_BALANCE_CACHE", str(blocker / "cache"))
    assert cached_arrays("thing", [1], counting(calls))["a"][3] == 1.0 and len(calls) == 3


def volumes_without_and_with_cache(load_robot, tmp_path, monkeypatch):
    monkeypatch.setenv("OMPL_BALANCE_CACHE", "")
    computed = CollisionChecker(load_robot())._volumes
    monkeypatch.setenv("OMPL_BALANCE_CACHE", str(tmp_path))
    CollisionChecker(load_robot())  # fills the cache
    assert list(tmp_path.glob("*.npz"))
    return computed, CollisionChecker(load_robot())._volumes  # a new robot object: read from disk


def test_checker_volumes_from_the_cache_equal_computed_ones_arm3(tmp_path, monkeypatch):
    computed, read = volumes_without_and_with_cache(lambda: arm3_scene()[0], tmp_path, monkeypatch)
    for name, value in computed._asdict().items():
        np.testing.assert_array_equal(value, getattr(read, name), err_msg=name)


def test_checker_volumes_from_the_cache_equal_computed_ones_panda(tmp_path, monkeypatch):
    from ompl_balance.collision.robots import load_panda_vamp

    computed, read = volumes_without_and_with_cache(load_panda_vamp, tmp_path, monkeypatch)
    assert (computed.pair_table >= 0).any()  # the tables are among what was cached
    for name, value in computed._asdict().items():
        np.testing.assert_array_equal(value, getattr(read, name), err_msg=name)
