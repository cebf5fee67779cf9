"""ParamSet: OMPL's string semantics, range suggestions and refusals."""

import pytest

from ompl_balance import ParamSet


class Holder:
    def __init__(self):
        self.ratio, self.flag, self.count, self.mode = 1.0, True, 3, "a"

    def set_ratio(self, value):
        if value < 0:
            raise ValueError("ratio must be >= 0")
        self.ratio = value


@pytest.fixture
def params_and_holder():
    holder = Holder()
    params = ParamSet()
    params.declareParam("ratio", holder.set_ratio, lambda: holder.ratio, "0.:0.05:10.")
    params.declareParam("flag", lambda v: setattr(holder, "flag", v), lambda: holder.flag)
    params.declareParam("count", lambda v: setattr(holder, "count", v), lambda: holder.count, "0:1:100")
    params.declareParam("mode", lambda v: setattr(holder, "mode", v), lambda: holder.mode, choices=("a", "b"))
    return params, holder


def test_types_are_inferred_and_values_are_strings(params_and_holder):
    params, holder = params_and_holder
    assert params.getParams() == {"ratio": "1.0", "flag": "1", "count": "3", "mode": "a"}
    assert params.setParam("ratio", "0.25") and holder.ratio == 0.25
    assert params.setParam("count", "7") and holder.count == 7
    assert params.setParam("mode", "b") and holder.mode == "b"


@pytest.mark.parametrize(
    ("text", "value"), [("0", False), ("1", True), ("true", True), ("false", False), ("TRUE", True)]
)
def test_booleans_in_ompl_forms(params_and_holder, text, value):
    params, holder = params_and_holder
    assert params.setParam("flag", text)
    assert holder.flag is value
    assert params.getParam("flag") == ("1" if value else "0")


def test_range_suggestions(params_and_holder):
    params, _ = params_and_holder
    assert params.getRangeSuggestion("ratio") == "0.:0.05:10."
    assert params.getRangeSuggestion("flag") == "0,1"
    assert params.getRangeSuggestion("mode") == "a,b"


@pytest.mark.parametrize(
    ("name", "text"),
    [
        ("ratio", "abc"),
        ("ratio", "-1"),
        ("ratio", "nan"),
        ("ratio", "inf"),
        ("flag", "yes"),
        ("count", "2.5"),
        ("mode", "c"),
        ("unknown", "1"),
    ],
)
def test_refusals_return_false_and_change_nothing(params_and_holder, name, text):
    params, _holder = params_and_holder
    before = params.getParams()
    assert params.setParam(name, text) is False
    assert params.getParams() == before


def test_set_params_tries_each_and_reports(params_and_holder):
    params, holder = params_and_holder
    assert params.setParams({"ratio": "2", "flag": "0"})
    assert not params.setParams({"ratio": "3", "bogus": "1"})
    assert holder.ratio == 3.0  # OMPL sets the good entries even when one is refused
    assert params.setParams({"ratio": "4", "bogus": "1"}, ignore_unknown=True)
    assert holder.ratio == 4.0


def test_introspection(params_and_holder):
    params, _ = params_and_holder
    assert params.hasParam("ratio") and not params.hasParam("nope") and "mode" in params
    assert params.getParamNames() == ["ratio", "flag", "count", "mode"]
    assert len(params) == 4
    with pytest.raises(KeyError, match="unknown parameter 'nope'"):
        params.getParam("nope")


def test_unsupported_type_is_a_declaration_error():
    with pytest.raises(TypeError, match="unsupported type"):
        ParamSet().declareParam("x", lambda v: None, lambda: [1, 2])
