"""A third-party constraint plugin package, registered only through its entry points (dist-info beside it)."""


def max_sum(options):
    """Feasible when the named parameters sum to at most `limit`."""
    names, limit = list(options["names"]), float(options["limit"])

    def constraint(params):
        return sum(params[n] for n in names) <= limit
    return constraint


def exploding(options):
    """A plugin whose constraint raises, as a broken instrument driver might."""
    def constraint(params):
        raise RuntimeError("interlock controller unreachable")
    return constraint


def gate(options):
    """Feasible everywhere, vectorized. While the file `hold` exists, a call writes `<hold>.held` and waits until
    `hold` is removed (at most `timeout_s`): a test holds a recommendation in the middle of its optimization, however
    fast the machine, and releases it once its cancel or stop request has been taken."""
    import time
    from pathlib import Path

    import numpy as np

    from gryffin_ros.planner import vectorized

    hold = Path(options["hold"])
    held = hold.with_name(hold.name + ".held")
    timeout_s = float(options.get("timeout_s", 120.0))

    @vectorized
    def constraint(columns):
        if hold.exists():
            held.touch()
            deadline = time.monotonic() + timeout_s
            while hold.exists() and time.monotonic() < deadline:
                time.sleep(0.01)  # polls the condition (the file's removal), not a stand-in for it
        return np.ones(len(next(iter(columns.values()))), dtype=bool)
    return constraint
