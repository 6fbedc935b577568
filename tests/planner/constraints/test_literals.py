"""A constraint is never silently weaker than written: every option, value or name it uses must exist."""

import logging

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from gryffin_ros.planner import ConfigError, Planner

CATALYST = {"name": "catalyst", "type": "categorical", "options": ["Pd(PPh3)4", "CuI", "NiCl2"]}
T = {"name": "T", "type": "continuous", "low": 20.0, "high": 200.0}
N = {"name": "n", "type": "discrete", "low": 1, "high": 5}
OBJECTIVE = [{"name": "y", "goal": "max"}]


def load(constraints, parameters=(T, CATALYST, N)):
    return Planner({"parameters": list(parameters), "objectives": OBJECTIVE, "constraints": constraints}, seed=0)


def refusal(constraints, **kwargs) -> str:
    with pytest.raises(ConfigError) as info:
        load(constraints, **kwargs)
    return str(info.value)


THERMAL = "T < (80 if catalyst == 'Pd(PPh3)4' else 120 if catalyst == {} else 150)"


def test_the_misspelt_option_of_the_issue_is_refused_with_the_closest_option():
    load([THERMAL.format("'CuI'")])
    message = refusal([THERMAL.format("'cui'")])
    assert "'cui' is not an option of 'catalyst' (options: 'Pd(PPh3)4', 'CuI', 'NiCl2'); did you mean 'CuI'?" \
        in message
    assert THERMAL.format("'cui'") in message  # names the constraint
    assert "did you mean 'CuI'?" in refusal([THERMAL.format("'CuI '")])


@pytest.mark.parametrize("text, literal", [
    ("catalyst != 'Cul'", "'Cul'"),
    ("'NiCl' == catalyst or T < 50", "'NiCl'"),
    ("catalyst in ['CuI', 'Nii']", "'Nii'"),
    ("catalyst not in ('CuI', 'nicl2')", "'nicl2'"),
    ("T < 100 if catalyst == 'Pd(PPh3)' else T < 150", "'Pd(PPh3)'"),
    ("50 < T < 150 and not (catalyst == 'CUI')", "'CUI'"),
])
def test_every_comparison_form_with_a_non_option_is_refused(text, literal):
    message = refusal([text])
    assert f"{literal} is not an option of 'catalyst'" in message


@pytest.mark.parametrize("text, expected", [
    ("n == 7", "7 is not an allowed value of 'n' (values: 1, 2, 3, 4, 5); did you mean 5?"),
    ("n in [1, 2.5] or T < 40", "2.5 is not an allowed value of 'n'"),
    ("n != 0", "0 is not an allowed value of 'n'"),
    ("n == 'three'", "the string 'three' is compared with 'n', a discrete parameter"),
    ("T != 'hot'", "the string 'hot' is compared with 'T', a continuous parameter"),
    ("T * 2 != 'CuI'", "which is not a categorical parameter"),
    ("catalyst == 2", "'catalyst' is categorical and is compared with the number 2"),
    ("catalyst < 'D'", "'catalyst' is categorical: its options have no order"),
])
def test_numbers_and_strings_must_fit_the_parameter_they_are_compared_with(text, expected):
    assert expected in refusal([text])


def test_valid_comparisons_of_every_kind_load():
    load(["n <= 3 or T < 150", "n in [1, 2, 3.0] or catalyst != 'CuI'", "T >= 20.5 if n == 5 else T < 190",
          "catalyst not in ['NiCl2'] or n != 1"])


def test_a_named_constraint_is_named_in_the_refusal():
    message = refusal([{"expression": "catalyst == 'cu'", "name": "copper only"}])
    assert "('copper only')" in message and "'cu' is not an option" in message


def test_a_misspelt_parameter_name_gets_a_suggestion():
    assert "unknown name 'catalist'" in refusal(["catalist == 'CuI'"])
    assert "did you mean 'catalyst'?" in refusal(["catalist == 'CuI'"])


# ---- tables ----------------------------------------------------------------------------------------------------
def lookup(tmp_path, text, columns=None):
    table = tmp_path / "feasible.csv"
    table.write_text(text)
    options = {"file": str(table), **({"columns": columns} if columns else {})}
    return [{"plugin": "lookup", "options": options}]


def test_a_lookup_table_naming_no_option_is_refused_with_its_line(tmp_path):
    load(lookup(tmp_path, "catalyst,n\nCuI,1\nNiCl2,3\n"), parameters=(CATALYST, N))
    message = refusal(lookup(tmp_path, "catalyst,n\nCuI,1\nNiCI2,3\n"), parameters=(CATALYST, N))
    assert "line 3" in message and "'NiCI2' is not an option of 'catalyst'" in message
    assert "did you mean 'NiCl2'?" in message


@pytest.mark.parametrize("rows, expected", [
    ("CuI,9\n", "9 is not an allowed value of 'n'"),
    ("CuI,two\n", "'two' is not a number"),
    ("CuI,\n", "is empty"),
])
def test_a_lookup_table_value_outside_a_discrete_parameter_is_refused(tmp_path, rows, expected):
    message = refusal(lookup(tmp_path, "catalyst,n\nCuI,1\n" + rows), parameters=(CATALYST, N))
    assert expected in message and "line 3" in message


def test_a_lookup_table_value_outside_a_continuous_range_is_refused(tmp_path):
    message = refusal(lookup(tmp_path, "cat,temp\nCuI,50\nCuI,250\n", {"catalyst": "cat", "T": "temp"}),
                      parameters=(CATALYST, T))
    assert "line 3" in message and "250 is outside the range of 'T' [20, 200]" in message


def test_descriptors_of_an_unknown_option_are_refused_with_the_closest_option():
    spec = {**CATALYST, "descriptors": {"Pd(PPh3)4": [1.0], "CuI": [2.0], "NiCl2": [3.0], "Cui": [4.0]}}
    message = refusal([], parameters=(spec, T))
    assert "descriptors given for 'Cui'" in message and "did you mean 'CuI'?" in message


def test_a_mixture_naming_no_parameter_is_refused_with_the_closest_name():
    parts = [{"name": name, "type": "continuous", "low": 0.0, "high": 1.0} for name in ("water", "ethanol", "dmso")]
    load([{"mixture": {"components": ["water", "ethanol", "dmso"]}}], parameters=parts)
    message = refusal([{"mixture": {"components": ["water", "ethanol", "dmos"]}}], parameters=parts)
    assert "['dmos'] are not continuous parameters" in message and "did you mean 'dmso'?" in message
    message = refusal([{"mixture": {"components": ["water", "ethanol", "dmso"], "bounds": {"etanol": [0, 0.5]}}}],
                      parameters=parts)
    assert "'etanol', which is not a component" in message and "did you mean 'ethanol'?" in message


# ---- constraints that constrain nothing ----------------------------------------------------------------------
def test_a_constraint_that_excludes_nothing_is_warned_about(caplog):
    with caplog.at_level(logging.WARNING, logger="gryffin_ros"):
        planner = load(["T < 500", "n <= 4", {"expression": "n < 10 or catalyst == 'CuI'", "name": "always"}])
        warnings = planner.constraint_warnings
    assert len(warnings) == 2
    assert "'T < 500' excludes no point" in warnings[0] and "uniform samples" in warnings[0]
    assert "'always' excludes no point" in warnings[1]
    assert [r.getMessage() for r in caplog.records if "excludes no point" in r.getMessage()] == warnings


def test_over_a_finite_space_the_check_is_exact():
    planner = load(["n <= 4 or catalyst != 'NiCl2'", "n < 6"], parameters=(CATALYST, N))
    assert planner.feasible_fraction.value == pytest.approx(14 / 15)
    [warning] = planner.constraint_warnings
    assert "'n < 6'" in warning and "any of the 15 points of the search space" in warning


def test_constraints_that_exclude_something_and_solved_mixture_bounds_raise_no_warning():
    assert load([THERMAL.format("'CuI'"), "n != 3 or T > 40"]).constraint_warnings == []
    # the solved component's bounds (dmso = 1 - water - ethanol within [0, 1]) are the planner's own, not the user's
    parts = [{"name": name, "type": "continuous", "low": 0.0, "high": 1.0} for name in ("water", "ethanol", "dmso")]
    assert load([{"mixture": {"components": ["water", "ethanol", "dmso"]}}], parameters=parts)\
        .constraint_warnings == []


def test_a_constraint_that_excludes_everything_is_still_an_error():
    from gryffin_ros.planner import NoFeasiblePointError
    with pytest.raises(NoFeasiblePointError):
        load(["n > 5"], parameters=(CATALYST, N)).feasible_fraction  # noqa: B018


# ---- property: a mutated literal is always refused, the unmutated expression always loads -------------------
LETTERS = "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789()-+ "


@st.composite
def spaces(draw):
    option = st.text(LETTERS, min_size=1, max_size=8).map(str.strip).filter(bool)
    parameters = []
    for i in range(draw(st.integers(1, 3))):
        options = draw(st.lists(option, min_size=2, max_size=5, unique=True))
        parameters.append({"name": f"c{i}", "type": "categorical", "options": options})
    for i in range(draw(st.integers(0, 2))):
        if draw(st.booleans()):
            low = draw(st.integers(-5, 5))
            parameters.append({"name": f"d{i}", "type": "discrete", "low": low, "high": low + draw(st.integers(1, 6))})
        else:
            values = draw(st.lists(st.sampled_from([0.5, 1.0, 1.5, 2.0, 4.0, 8.0, 10.0]), min_size=2, max_size=5,
                                   unique=True))
            parameters.append({"name": f"d{i}", "type": "discrete", "options": values})
    for i in range(draw(st.integers(1, 2))):
        parameters.append({"name": f"x{i}", "type": "continuous", "low": 0.0, "high": 10.0})
    return parameters


class Slot:
    """A literal of an expression; `render` writes it, or its mutation when this slot is the one mutated."""

    def __init__(self, parameter, value):
        self.parameter, self.value = parameter, value

    def render(self, mutated):
        return repr(mutated[1] if mutated and mutated[0] is self else self.value)


@st.composite
def comparisons(draw, parameters, slots):
    finite = [p for p in parameters if p["type"] != "continuous"]
    continuous = [p for p in parameters if p["type"] == "continuous"]
    p = draw(st.sampled_from(finite))
    options = p["options"] if "options" in p else list(range(p["low"], p["high"] + 1))
    form = draw(st.sampled_from(["eq", "eq_left", "ne", "in", "not_in", "inside_if"]))
    if form in ("in", "not_in"):
        chosen = draw(st.lists(st.sampled_from(options), min_size=1, max_size=len(options), unique=True))
        members = [Slot(p, v) for v in chosen]
        slots.extend(members)
        op = "in" if form == "in" else "not in"
        return lambda m: f"{p['name']} {op} [{', '.join(s.render(m) for s in members)}]"
    slot = Slot(p, draw(st.sampled_from(options)))
    slots.append(slot)
    if form == "eq":
        return lambda m: f"{p['name']} == {slot.render(m)}"
    if form == "eq_left":
        return lambda m: f"{slot.render(m)} == {p['name']}"
    if form == "ne":
        return lambda m: f"{p['name']} != {slot.render(m)}"
    x = draw(st.sampled_from(continuous))["name"]
    a, b = draw(st.integers(1, 9)), draw(st.integers(1, 9))
    return lambda m: f"{x} < ({a} if {p['name']} == {slot.render(m)} else {b})"


@st.composite
def expressions(draw, parameters, slots, depth=0):
    if depth >= 2 or draw(st.booleans()):
        return draw(comparisons(parameters, slots))
    form = draw(st.sampled_from(["and", "or", "not", "if"]))
    left = draw(expressions(parameters, slots, depth + 1))
    if form == "not":
        return lambda m: f"not ({left(m)})"
    right = draw(expressions(parameters, slots, depth + 1))
    if form == "if":
        test = draw(comparisons(parameters, slots))
        return lambda m: f"({left(m)}) if {test(m)} else ({right(m)})"
    return lambda m: f"({left(m)}) {form} ({right(m)})"


def mutate(draw, value):
    """A small typo of an option: another case, a blank around it, a letter changed, added or dropped; for a
    number, a value next to it."""
    if not isinstance(value, str):
        return value + draw(st.sampled_from([0.25, -0.25, 1e-3, 100]))
    kind = draw(st.sampled_from(["case", "blank", "replace", "insert", "delete"]))
    if kind == "case":
        return value.swapcase()
    if kind == "blank":
        return draw(st.sampled_from([value + " ", " " + value]))
    i = draw(st.integers(0, len(value) - 1))
    letter = draw(st.sampled_from("xqZ7"))
    if kind == "replace":
        return value[:i] + letter + value[i + 1:]
    if kind == "insert":
        return value[:i] + letter + value[i:]
    return value[:i] + value[i + 1:]


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_a_mutated_literal_is_always_refused_and_the_original_always_loads(data):
    parameters = data.draw(spaces())
    slots = []  # fresh for every example: nothing is shared between examples
    render = data.draw(expressions(parameters, slots))
    config = {"parameters": parameters, "objectives": OBJECTIVE}
    Planner({**config, "constraints": [render(None)]}, seed=0)  # loads (V_C is not estimated here)

    slot = data.draw(st.sampled_from(slots))
    typo = mutate(data.draw, slot.value)
    options = slot.parameter.get("options") or list(range(slot.parameter["low"], slot.parameter["high"] + 1))
    assume(typo not in options and (isinstance(typo, str) or not np.isclose(typo, options).any()))
    text = render((slot, typo))
    assert text != render(None)
    with pytest.raises(ConfigError) as info:
        Planner({**config, "constraints": [text]}, seed=0)
    message = str(info.value)
    assert repr(typo) in message and f"'{slot.parameter['name']}'" in message


@pytest.mark.parametrize("spec, expected", [
    ("n == True", "is compared with True"),
    ({"expression": "n < 3", "options": {"strict": True}}, "an expression takes none"),
    ({"plugin": "expression", "options": {"expression": "n < 3", "strict": True}}, "unknown option(s) ['strict']"),
])
def test_nothing_a_constraint_says_is_ignored(spec, expected):
    assert expected in refusal([spec])
