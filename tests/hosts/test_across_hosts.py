"""The planner on one host, two instruments on two others (network namespaces joined by a switch: real separate
network stacks, real DDS over UDP between them), discovery set up as the README tells a lab: a closed-loop campaign
with the instruments sharing the work, and network partitions in the middle of it."""

import os
import threading
import time

import pytest

from benchmarks import netlab
from gryffin_ros.paths import share_path

REASON = netlab.unavailable()
pytestmark = pytest.mark.skipif(REASON is not None, reason=f"network namespaces: {REASON}")

CONFIG = share_path("examples") / "flow_reactor.yaml"
BUDGET = 16
CUT_S = 12.0  # longer than the DDS lease (10 s in the package's resources/fastdds_profile.xml): peers drop each other
HANG_S = 180.0


@pytest.fixture
def lab():
    with netlab.NetLab(["planner", "inst1", "inst2"]) as made:
        yield made


def campaign(lab, tmp_path, discovery: str) -> netlab.LabCampaign:
    domain = int(os.environ.get("ROS_DOMAIN_ID", "0") or 0)
    run = netlab.LabCampaign(lab, tmp_path, CONFIG, discovery, domain)
    run.start()
    return run


def reach(run: netlab.LabCampaign, count: int, timeout: float = HANG_S) -> None:
    assert netlab.wait_until(lambda: run.alive() and run.count() >= count, timeout), \
        f"{run.count()} of {count} experiments stored\n{run.log(run.planner)[-2000:]}"


def finish(run: netlab.LabCampaign, before: float | None = None) -> dict:
    """Run to the budget, then check: everything measured by then is stored (its report may still be on its way:
    sent again until acknowledged), and every experiment proposed before `before` was completed."""
    owed = run.proposed_before(before) if before is not None else set()
    result = run.settle(BUDGET, owed, HANG_S)
    assert result["exit_codes"] == {h: 0 for h in result["exit_codes"]}, result
    assert result["settled"] and result["lost"] == 0 and result["owed_not_done"] == 0, result
    assert result["run_twice"] == 0 and result["other_rejections"] == 0, result
    return result


def test_the_lab_network_is_the_namespaces_alone(lab):
    for host in lab.names:
        assert lab.interfaces(host) == ["lo", "eth0"]
    assert sorted(lab.interfaces()) == sorted(["lo", "br0", *lab.names])  # the switch: no port to the machine


def test_an_instrument_cut_off_for_longer_than_the_lease(lab, tmp_path):
    run = campaign(lab, tmp_path, "static")
    reach(run, 4)
    lab.cut("inst1")
    cut_at = time.time()
    time.sleep(CUT_S)  # the partition itself: its length is the experiment
    # a report on the wire at the moment of the cut may still be stored just after it: look from 1 s on
    during = [i for _, received, i in run.observations() if received > cut_at + 1.0]
    lab.restore("inst1")
    restored = time.time()
    assert during and all(i.endswith("inst2") for i in during), during  # the other instrument went on alone
    # the cut instrument comes back: its first result after the link returned (the budget alone does not wait for
    # it: the other instrument may reach the budget meanwhile, as it ran alone for the whole cut)
    back = lambda: [r for _, r, i in run.observations() if i.endswith("inst1") and r > restored]  # noqa: E731
    assert netlab.wait_until(lambda: run.alive() and back(), HANG_S), "the cut instrument never reported again"
    finish(run, before=restored)


def test_the_planner_cut_off_for_longer_than_the_lease(lab, tmp_path):
    """Also the plain shared campaign: both instruments take experiments, subnet discovery."""
    run = campaign(lab, tmp_path, "subnet")
    reach(run, 4)
    lab.cut("planner")
    time.sleep(CUT_S)
    lab.restore("planner")
    restored = time.time()
    finish(run, before=restored)
    assert {i.rsplit("_", 1)[-1] for _, received, i in run.observations() if received > restored} == {"inst1", "inst2"}


def test_a_flapping_planner_link(lab, tmp_path):
    run = campaign(lab, tmp_path, "static")
    stop = threading.Event()

    def flap():  # down 1 s in every 5 s, for the whole campaign
        while not stop.wait(4.0):
            lab.cut("planner")
            stop.wait(1.0)
            lab.restore("planner")
    flapper = threading.Thread(target=flap, daemon=True)
    flapper.start()
    try:
        accounting = finish(run)
    finally:
        stop.set()
        flapper.join()
    assert accounting["stored"] >= BUDGET
