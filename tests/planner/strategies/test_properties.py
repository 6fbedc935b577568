"""Property tests: across random mixed spaces and random constraints, no proposal is ever infeasible, out of
bounds or of the wrong type, whichever acquisition optimizer runs."""

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gryffin_ros.planner import Genetic, Planner, Random


@st.composite
def problems(draw):
    """A random space, an anchor point known to be feasible, and constraints (text + independent Python check)."""
    n = draw(st.integers(1, 4))
    specs, anchor = [], {}
    for i in range(n):
        kind = draw(st.sampled_from(["continuous", "discrete", "categorical"]))
        name = f"p{i}"
        if kind == "continuous":
            low = draw(st.floats(-1000, 1000, allow_nan=False))
            span = draw(st.floats(0.01, 500))
            spec = {"name": name, "type": kind, "low": low, "high": low + span,
                    "periodic": draw(st.booleans())}
            anchor[name] = draw(st.floats(low, low + span))
        elif kind == "discrete":
            low = draw(st.integers(-20, 20))
            spec = {"name": name, "type": kind, "low": low, "high": low + draw(st.integers(1, 15))}
            anchor[name] = draw(st.integers(spec["low"], spec["high"]))
        else:
            options = [f"o{j}" for j in range(draw(st.integers(2, 5)))]
            spec = {"name": name, "type": kind, "options": options}
            if draw(st.booleans()):
                spec["descriptors"] = {o: [draw(st.floats(-5, 5)), float(j)] for j, o in enumerate(options)}
            anchor[name] = draw(st.sampled_from(options))
        specs.append(spec)
    numeric = [s["name"] for s in specs if s["type"] != "categorical"]
    categorical = [s for s in specs if s["type"] == "categorical"]
    texts, checks = [], []
    for _ in range(draw(st.integers(0, 3))):
        if numeric and (not categorical or draw(st.booleans())):
            weights = {name: draw(st.floats(-2, 2)) for name in numeric}
            margin = draw(st.floats(0, 5))
            bound = sum(w * anchor[k] for k, w in weights.items()) + margin
            texts.append(" + ".join(f"({w!r}) * {k}" for k, w in weights.items()) + f" <= {bound!r}")
            checks.append(lambda p, w=weights, b=bound: sum(c * p[k] for k, c in w.items()) <= b + 1e-9)
        elif categorical:
            spec = draw(st.sampled_from(categorical))
            banned = draw(st.sampled_from([o for o in spec["options"] if o != anchor[spec["name"]]]))
            texts.append(f"{spec['name']} != '{banned}'")
            checks.append(lambda p, k=spec["name"], b=banned: p[k] != b)
    return specs, texts, checks, objective_against(texts, checks, numeric)


def objective_against(texts, checks, numeric):
    """An objective whose optimum lies outside the first linear constraint, so the optimizers press against it."""
    linear = [t for t in texts if "<=" in t]
    if not linear:
        return lambda p: sum(float(p[k]) for k in numeric)
    check = checks[texts.index(linear[0])]
    weights = check.__defaults__[0]
    return lambda p: -sum(w * p[k] for k, w in weights.items())


def feasible_fraction(specs, checks, samples=4000, seed=0):
    """The feasible fraction measured independently of the planner, by uniform sampling in users' units."""
    rng = np.random.default_rng(seed)
    columns = {}
    for spec in specs:
        if spec["type"] == "continuous":
            columns[spec["name"]] = rng.uniform(spec["low"], spec["high"], samples).tolist()
        elif spec["type"] == "discrete":
            columns[spec["name"]] = rng.integers(spec["low"], spec["high"] + 1, samples).tolist()
        else:
            columns[spec["name"]] = rng.choice(spec["options"], samples).tolist()
    rows = [dict(zip(columns, values)) for values in zip(*columns.values())]
    return np.mean([all(check(row) for check in checks) for row in rows])


def assert_clear_refusal(exc, specs, checks):
    """Running out of new points, or a feasible set too small to sample, may end a campaign; nothing else may."""
    name = type(exc).__name__
    assert name in ("ExhaustedSpaceError", "NoFeasiblePointError"), exc
    if name == "NoFeasiblePointError":
        assert feasible_fraction(specs, checks) < 0.01, exc


def assert_valid(specs, checks, params):
    assert set(params) == {s["name"] for s in specs}
    for spec in specs:
        value = params[spec["name"]]
        if spec["type"] == "continuous":
            assert type(value) is float and spec["low"] <= value <= spec["high"]
        elif spec["type"] == "discrete":
            assert type(value) is int and spec["low"] <= value <= spec["high"]
        else:
            assert type(value) is str and value in spec["options"]
    for check in checks:
        assert check(params), params


@settings(max_examples=20, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(problem=problems(), optimizer=st.sampled_from(["adam", "genetic"]), seed=st.integers(0, 2**31))
def test_planner_proposals_are_always_feasible_in_bounds_and_typed(problem, optimizer, seed):
    specs, texts, _, _ = problem
    config = {"parameters": specs, "objectives": [{"name": "y", "goal": "min"}], "constraints": texts,
              "general": {"acquisition_optimizer": optimizer, "num_random_samples": 15}}
    exercise(Planner(config, seed=seed), problem, rounds=5, seed=seed)


def exercise(planner, problem, rounds, seed):
    """Ask two proposals at a time, check each, report it (one in ten fails); a clear refusal may end the campaign."""
    specs, _, checks, objective = problem
    rng = np.random.default_rng(seed)
    for _ in range(rounds):
        try:
            proposals = planner.ask(2)
        except Exception as exc:
            assert_clear_refusal(exc, specs, checks)
            return
        for proposal in proposals:
            assert_valid(specs, checks, proposal.params)
            y = None if rng.random() < 0.1 else objective(proposal.params)
            planner.tell({**proposal.params, "y": y, "experiment_id": proposal.experiment_id})


@settings(max_examples=15, deadline=None, derandomize=True)
@given(problem=problems(), seed=st.integers(0, 2**31))
def test_baseline_proposals_are_always_feasible(problem, seed):
    specs, texts, checks, objective = problem
    config = {"parameters": specs, "objectives": [{"name": "y", "goal": "min"}], "constraints": texts}
    for strategy in (Random, Genetic):
        planner = strategy(config, seed=seed)
        for _i in range(25):
            try:
                (proposal,) = planner.ask()
            except Exception as exc:
                assert_clear_refusal(exc, specs, checks)
                break
            assert_valid(specs, checks, proposal.params)
            planner.tell({**proposal.params, "y": objective(proposal.params), "experiment_id": proposal.experiment_id})
