"""The from-scratch benchmark's hidden failures and one short campaign (benchmarks/from_scratch.py)."""

import math

from benchmarks import from_scratch, portfolio_tasks


def test_the_hidden_rules_fail_cs2co3_and_hot_dmf_only():
    task = portfolio_tasks.TASKS["m_coupling"]()
    base, solvent = task.bases.index, task.solvents.index
    assert from_scratch.hidden_failure(task, [0, base("Cs2CO3"), solvent("THF"), 40.0, 2.0, 1.0])
    assert from_scratch.hidden_failure(task, [0, base("K3PO4"), solvent("DMF"), 115.0, 2.0, 1.0])
    assert not from_scratch.hidden_failure(task, [0, base("K3PO4"), solvent("DMF"), 105.0, 2.0, 1.0])
    assert not from_scratch.hidden_failure(task, [0, base("K3PO4"), solvent("EtOH"), 70.0, 2.0, 1.0])


def test_a_short_campaign_counts_its_failures_and_keeps_the_best_success():
    name, seed, failed, late, best = from_scratch.run(("m_coupling", 0, True, 6, 0.0))
    assert (name, seed) == ("m_coupling", 0) and 0 <= late <= failed <= 6
    assert math.isinf(best) == (failed == 6)
    assert math.isinf(best) or -1.0 < best < 1.0  # a yield minus the reagent and time costs


def test_failures_at_random_fail_experiments_wherever_they_are():
    name, seed, failed, late, best = from_scratch.run(("m_coupling", 3, False, 6, 0.999))
    assert failed == 6 and late == 3 and math.isinf(best)
