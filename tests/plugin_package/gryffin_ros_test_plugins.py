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
