"""The rating of benchmarks/rating.py: 2 in a small ball, 1 in a shell around it, 0 elsewhere, as its docstring says."""

import math

from benchmarks.rating import CENTRE, WIDTH, rating


def point(r: float) -> dict:
    """A point at distance r from the centre, along x2."""
    return {"x0": CENTRE[0], "x1": CENTRE[1], "x2": CENTRE[2] + r}


def test_the_rating_is_two_in_the_ball_one_in_the_shell_and_zero_outside():
    top, shell = math.sqrt(WIDTH * math.log(1.5)), math.sqrt(WIDTH * math.log(3.0))
    assert round(top, 3) == 0.142 and round(shell, 3) == 0.234  # the radii the docstring gives
    assert rating(point(0.0)) == 2.0 and rating(point(top - 1e-3)) == 2.0
    assert rating(point(top + 1e-3)) == 1.0 and rating(point(shell - 1e-3)) == 1.0
    assert rating(point(shell + 1e-3)) == 0.0 and rating({"x0": 0.0, "x1": 1.0, "x2": 0.0}) == 0.0
    # the ball lies inside the unit cube, so its volume is the share of the cube the docstring gives
    assert all(c - top > 0 and c + top < 1 for c in CENTRE)
    assert round(4 / 3 * math.pi * top ** 3, 4) == 0.0121
