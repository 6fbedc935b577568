"""When a campaign has stalled: its last experiments, after every option had been explored, stopped improving its best
result. The GP's ask after such a stretch predicts what the campaign has not tried at the results' mean
(`GaussianProcess.at_results_mean`).

A GP fitted to results most of which sit on a plateau (nothing reacted: the merit is only the reagents' and time's
cost) puts its constant mean near that plateau, so it predicts every untried combination of options there, and its
expected improvement stays beside the incumbent however little that pays. m_coupling from the planner's first
proposal with hidden failures, seed 0: 8 of experiments 25-33 on SPhos / K2CO3 / toluene, each result -0.233 to
-0.235, the optimum -0.74, ending 0.504 short; with this rule its ask after experiment 33 ran SPhos / Et3N / toluene
(-0.563 at once) and it ended 0.082 short (24 such campaigns: worst 0.504 -> 0.099, the harness start and campaigns
without failures as before). One such ask per window at most: with one every other ask while stalled, campaigns that
had found a good combination and refined it in steps below the tolerance lost their refinement (the harness start,
12 seeds: 10 worse). Experiments that ran an option for its first or second time (the covering rule's,
`strategies.gryffin`) explore on purpose and start no stall. benchmarks/README.md "Stuck campaigns on mixed spaces",
round twenty-two.

When a campaign has settled: most of its last experiments ran one combination of the options of its small categorical
parameters, improving or not. The GP's ask after such a stretch runs the best result's conditions with one option
changed (`strategies.gryffin`). A campaign that crawls toward the best conditions of a mediocre combination improves
on nearly every experiment, so it never stalls: m_amination (held out, `benchmarks/portfolio_tasks.py`), seed 10, ran
BrettPhos / LHMDS / toluene in 19 of experiments 17-40 and ended at 0.41 (that combination's best is 0.42; RuPhos
with the same base and solvent gives 0.79, the optimum). With this rule its asks after experiments 22 and 30 ran
Xantphos, then RuPhos, at the best conditions so far; RuPhos gave 0.735 at once, and the campaign ended 0.002 short
(12 seeds: worst 0.380 -> 0.199, mean 0.094 -> 0.063; the four tuned mixed tasks within noise or better).
benchmarks/README.md "Stuck campaigns on mixed spaces", round twenty-three.
"""

from __future__ import annotations

import numpy as np

# The stretch of experiments (failed ones included) whose improvement of the best result decides, and the smallest
# improvement, as a share of the results' range, that is not a stall.
STALL_WINDOW = 8
STALL_TOLERANCE = 0.01
# How many of the last STALL_WINDOW experiments ran one combination of options in a settled campaign (at most one
# settled ask per window): 8 of 8 missed the campaign above, whose crawl tried a neighbouring solvent now and then.
SETTLE_LEAST = 6


def stall(merits: np.ndarray, since: int = 0, window: int = STALL_WINDOW, tolerance: float = STALL_TOLERANCE
          ) -> float | None:
    """merits: (n,) each experiment's merit, in order (lower is better; NaN for a failed experiment). -> How much the
    last `window` experiments improved the best merit, as a share of the range of the results so far, if the ask after
    them is a stalled ask, else None. The ask after m experiments is one when m >= max(2 window, since + window), the
    best of the m improved on the best of the first m - window by less than `tolerance` of the range of the m's
    results, and none of the previous window - 1 asks was one. `since`: the first `since` experiments explored on
    purpose (`exploring_until`); no window reaches into them."""
    merits = np.asarray(merits, dtype=float)
    failed = np.isnan(merits)
    best = np.fmin.accumulate(np.where(failed, np.inf, merits))
    worst = np.fmax.accumulate(np.where(failed, -np.inf, merits))
    last, gain = None, None
    for m in range(max(2 * window, since + window), len(merits) + 1):
        if not np.isfinite(best[m - window - 1]):  # nothing had succeeded before the window
            continue
        improved = best[m - window - 1] - best[m - 1]
        span = worst[m - 1] - best[m - 1]
        share = improved / span if span > 0 else improved
        if share < tolerance and (last is None or m - last >= window):
            last, gain = m, float(share)
    return gain if last == len(merits) else None


def exploring_until(options: np.ndarray, tries: int) -> int:
    """options: (n, P) the option each experiment ran of each small categorical parameter (the planner's covering
    rule runs each one `tries` times first). -> The number of experiments up to and including the last one that ran
    some option for the first to `tries`-th time (0 if none did): that one explored the option, it was no attempt to
    improve on the best result."""
    last = 0
    for column in np.rint(np.asarray(options, dtype=float)).astype(int).T:
        order = np.argsort(column, kind="stable")  # each option's runs together, in the order they were made
        _, start, runs = np.unique(column[order], return_index=True, return_counts=True)
        last = max(last, int(order[start + np.minimum(tries, runs) - 1].max(initial=-1)) + 1)
    return last


def settled(options: np.ndarray, window: int = STALL_WINDOW, least: int = SETTLE_LEAST) -> np.ndarray | None:
    """options: (n, P) the option each experiment (observed, then pending) ran of each small categorical parameter, in
    order. -> The combination of options that `least` or more of the last `window` experiments ran, if the ask after
    them is a settled ask, else None. The ask after m experiments is one when m >= 2 window, `least` of experiments
    m - window + 1 .. m ran one combination, and none of the previous window - 1 asks was one."""
    combos = np.rint(np.asarray(options, dtype=float)).astype(int).reshape(len(options), -1)
    if len(combos) < 2 * window:
        return None
    _, codes = np.unique(combos, axis=0, return_inverse=True)
    recent = np.lib.stride_tricks.sliding_window_view(codes.ravel(), window)  # (n - window + 1, window)
    alike = (recent[:, :, None] == recent[:, None, :]).sum(axis=2)  # per window, per member: its combination's count
    last = None
    for m in np.flatnonzero(alike.max(axis=1) >= least) + window:  # experiments m - window + 1 .. m: alike enough
        if m >= 2 * window and (last is None or m - last >= window):
            last = int(m)
    if last != len(combos):
        return None
    return combos[len(combos) - window + int(np.argmax(alike[-1]))]
