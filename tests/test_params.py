"""ParamSet: OMPL's string semantics, range suggestions and refusals."""

import io
import itertools

import pytest

from ompl_balance import ParamSet
from ompl_balance.samplers import PassageSampler
from ompl_balance.worlds.boxes import get_problem


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


def test_introspection_lists_by_name_as_cpp_std_map(params_and_holder):
    params, holder = params_and_holder
    assert params.hasParam("ratio") and not params.hasParam("nope") and "mode" in params
    assert params.getParamNames() == ["count", "flag", "mode", "ratio"]
    assert params.getParamValues() == ["3", "1", "a", "1.0"]
    assert list(params.getParams()) == params.getParamNames() == list(params)
    assert params.size() == len(params) == 4
    with pytest.raises(KeyError, match="unknown parameter 'nope'"):
        params.getParam("nope")
    holder.count = 9  # values are read live from the getters
    assert params.getParamValues()[0] == "9" and params.getParam("count") == "9"


def test_generic_param_methods(params_and_holder):
    params, holder = params_and_holder
    ratio = params["ratio"]
    assert ratio.getName() == "ratio" and ratio.getValue() == "1.0"
    assert ratio.setValue("2.5") is True and holder.ratio == 2.5 and ratio.getValue() == "2.5"
    assert ratio.setValue("-1") is False and holder.ratio == 2.5  # the setter refused it
    assert ratio.setValue(0.5) is True and holder.ratio == 0.5  # a Python value, as its string form
    assert ratio.getRangeSuggestion() == "0.:0.05:10."
    ratio.setRangeSuggestion("0.:1.:5.")
    assert params.getRangeSuggestion("ratio") == "0.:1.:5."
    ratio.setName("r")
    assert ratio.getName() == "r"
    assert params["flag"].getValue() == "1" and params["flag"].setValue("false") and holder.flag is False


def test_print_writes_name_equals_value_lines_by_name(params_and_holder, capsys):
    params, _ = params_and_holder
    out = io.StringIO()
    params.print(out)
    assert out.getvalue() == "count = 3\nflag = 1\nmode = a\nratio = 1.0\n"
    params.print()  # standard output by default, as C++'s std::cout
    assert capsys.readouterr().out == out.getvalue()


def test_add_remove_include_and_clear(params_and_holder):
    params, holder = params_and_holder
    other = ParamSet()
    other.declareParam("size", lambda v: setattr(holder, "size", v), lambda: 5, "1:1:10")
    params.include(other, "sampler")
    assert params.getParam("sampler.size") == "5" and params.setParam("sampler.size", "7") and holder.size == 7
    params.include(other)
    assert params.hasParam("size")
    params.remove("size")
    params.remove("size")  # nothing to remove: no error, as C++
    assert not params.hasParam("size")
    params.add(other["size"])
    assert params.hasParam("size")
    params.clear()
    assert params.size() == 0 and params.getParams() == {}


def test_unsupported_type_is_a_declaration_error():
    with pytest.raises(TypeError, match="unsupported type"):
        ParamSet().declareParam("x", lambda v: None, lambda: [1, 2])


def test_set_params_of_one_table_is_checked_on_the_result_whatever_the_order():
    """PassageSampler needs min_colliding <= max_colliding <= neighbours: lowering the
    neighbours and the maximum together works in either order, as one combination."""
    si = get_problem("narrow_gap").setup().getSpaceInformation()
    values = {"neighbours": "4", "max_colliding": "3", "min_colliding": "2"}
    results = set()
    for order in itertools.permutations(values):
        sampler = PassageSampler(si)
        assert sampler.params().setParams({name: values[name] for name in order})
        results.add(tuple(sampler.params().getParamValues()))
    assert len(results) == 1
    sampler = PassageSampler(si)
    before = sampler.params().getParams()
    assert not sampler.params().setParams({"neighbours": "4", "bogus": "1"})  # 4 < max_colliding 7
    assert sampler.params().getParams() == before  # the combination is refused as a whole
