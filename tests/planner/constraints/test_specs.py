"""Constraint config entries are typed once, when the config loads (`ConstraintSpec`): their shape is checked there
with their position, a plugin's relative file is taken from the config's folder, an expression is parsed once for all
its readers, and the plugin form of an expression is that expression."""

import ast

import numpy as np
import pytest

from gryffin_ros.planner import ConfigError, Planner
from gryffin_ros.planner.config import load_config
from gryffin_ros.planner.constraints import ConstraintSpec, KnownConstraints, LinearEqualities, expressions

PARAMETERS = [{"name": "a", "type": "continuous", "low": 0.0, "high": 1.0},
              {"name": "b", "type": "continuous", "low": 0.0, "high": 1.0},
              {"name": "c", "type": "continuous", "low": 0.0, "high": 1.0}]


def config(constraints):
    return {"parameters": PARAMETERS, "objectives": [{"name": "y", "goal": "min"}], "constraints": constraints}


def test_every_entry_form_is_typed_at_load_with_its_position_and_label(tmp_path):
    (tmp_path / "feasible.csv").write_text("a,b\n0.5,0.5\n")
    loaded = load_config(config([
        "a + b <= 1.5",
        {"expression": "a < 0.9", "name": "pump"},
        {"plugin": "lookup", "options": {"file": "feasible.csv", "columns": {"a": "a", "b": "b"}}},
        {"plugin": "expression", "options": {"expression": "c > 0.1"}, "name": "cooling"},
        {"mixture": {"components": ["a", "b", "c"], "total": 1.0}},
    ]), base_dir=tmp_path)
    specs = loaded.constraint_specs
    assert all(isinstance(s, ConstraintSpec) for s in specs)
    assert [s.position for s in specs] == [0, 1, 2, 3, 4]
    assert [s.expression for s in specs] == ["a + b <= 1.5", "a < 0.9", None, "c > 0.1", None]
    assert [s.name for s in specs] == [None, "pump", None, "cooling", None]
    assert specs[2].plugin == "lookup" and specs[2].options["file"] == str(tmp_path / "feasible.csv")
    assert specs[4].mixture == {"components": ["a", "b", "c"], "total": 1.0}


@pytest.mark.parametrize("entry, message", [
    (42, "constraints[1] must be an expression string or a mapping"),
    ({"when": "a < 1"}, "constraints[1]: unknown key(s) ['when']"),
    ({"expression": "a < 1", "plugin": "lookup"}, "constraints[1]: give 'expression' or 'plugin', not both"),
    ({"expression": "a < 1", "options": {}}, "constraints[1]: 'options' belong to a plugin"),
    ({"name": "x"}, "constraints[1]: needs an 'expression' string or a 'plugin' name"),
    ({"plugin": "lookup", "options": ["file.csv"]}, "constraints[1]: constraint plugin 'lookup': 'options' must be"),
    ({"plugin": "expression", "options": {"expression": "a < 1", "strict": True}}, "unknown option(s) ['strict']"),
    ({"mixture": {"components": ["a", "b"]}, "total": 1}, "constraints[1]: a mixture is"),
])
def test_a_malformed_entry_is_refused_when_the_config_loads_naming_its_position(entry, message):
    with pytest.raises(ConfigError) as info:
        load_config(config(["a < 0.9", entry]))
    assert message in str(info.value)


def test_each_expression_is_parsed_once_for_the_planner_and_all_its_readers(monkeypatch):
    # made-up texts so that the parse cache of other tests cannot hold them
    texts = ["a + b <= 1.25 + 0.001 * 7", "0.003 * 11 < c", "a + b + c == 1 + 0.0001 * 3"]
    parsed = []
    real = ast.parse
    monkeypatch.setattr(expressions.ast, "parse", lambda text, *args, **kwargs: parsed.append(text) or real(
        text, *args, **kwargs))
    planner = Planner(config(texts), seed=0)
    planner.ask(2)
    # ast.parse is the standard library's: other callers (torch's script compiler) parse their own sources
    assert sorted(t for t in parsed if t in texts) == sorted(texts)


def test_the_plugin_form_of_an_expression_is_that_expression():
    """Written as {plugin: expression, ...}, a linear inequality gives the same half-spaces (the planner samples the
    polytope exactly) and an equality is solved exactly, as in the expression form."""
    space = Planner(config([]), seed=0).space
    for text in ("a + 2 * b <= 1", "a + b <= 0.5"):
        plugin = KnownConstraints.build(space, [{"plugin": "expression", "options": {"expression": text}}])
        written = KnownConstraints.build(space, [text])
        A, b, complete = plugin.halfspaces()
        A_written, b_written, complete_written = written.halfspaces()
        assert np.array_equal(A, A_written) and np.array_equal(b, b_written) and complete and complete_written
    equalities, rest = LinearEqualities.split(
        [{"plugin": "expression", "options": {"expression": "a + b + c == 1"}}], load_config(config([])).space)
    assert equalities is not None and rest == []
    planner = Planner(config([{"plugin": "expression", "options": {"expression": "a + b + c == 1"}}]), seed=1)
    for proposal in planner.ask(3):
        # the third component is solved from the other two: exact up to the rounding of two additions
        assert abs(sum(proposal.params.values()) - 1.0) <= 4 * np.finfo(float).eps


def test_mixture_bounds_keep_the_mixture_position_in_their_messages():
    entry = {"mixture": {"components": ["a", "b", "c"], "total": 1.0, "bounds": {"a": [0.2, 0.4]}}}
    equalities, rest = LinearEqualities.split([ConstraintSpec.of("c < 0.9", 0), ConstraintSpec.of(entry, 1)],
                                              load_config(config([])).space)
    assert equalities is not None
    assert [(s.position, s.expression) for s in rest] == [(0, "c < 0.9"), (1, "0.2 <= a <= 0.4")]
