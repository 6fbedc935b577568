"""Campaign: one owner of the store, the planner and the bookkeeping — tested without DDS."""

import json
import sqlite3
import subprocess
import sys
import textwrap

import pytest

from gryffin_ros import messages
from gryffin_ros.campaign import Campaign, CampaignClosed, Rejected
from gryffin_ros.planner import ConfigError, ObservationError
from gryffin_ros.storage import StoreError

CONFIG = {
    "name": "campaign_test",
    "parameters": [{"name": "x", "type": "continuous", "low": 0.0, "high": 10.0},
                   {"name": "solvent", "type": "categorical", "options": ["THF", "DMF", "MeCN"]}],
    "objectives": [{"name": "y", "goal": "max"}],
    "constraints": ["x < 6 if solvent == 'THF' else x < 9"],
}


def report(proposal, value=1.0):
    return {"experiment_id": proposal.experiment_id, "params": proposal.params, "objectives": {"y": value}}


def stored_ids(path):
    with sqlite3.connect(path) as db:
        return [row[0] for row in db.execute("SELECT experiment_id FROM observations ORDER BY seq")]


def test_each_observation_is_validated_once_and_learnt_without_parsing_again(tmp_path, monkeypatch):
    campaign = Campaign(CONFIG, tmp_path / "c.sqlite", seed=0)
    calls = []
    parse = campaign.planner.parse_observation
    monkeypatch.setattr(campaign.planner, "parse_observation", lambda item: calls.append(item) or parse(item))
    for proposal in campaign.propose(3):
        campaign.observe(report(proposal))
    campaign.propose(1)  # learning and asking again parse nothing
    assert len(calls) == 3
    assert len(campaign.planner.observations) == 3


def test_an_observation_the_planner_cannot_rank_after_the_commit_is_neither_lost_nor_double_reported(
        tmp_path, monkeypatch):
    path = tmp_path / "c.sqlite"
    campaign = Campaign(CONFIG, path, seed=0)
    first, second = campaign.propose(2)
    best = campaign.planner.best

    def broken():
        raise RuntimeError("ranking crashed")
    monkeypatch.setattr(campaign.planner, "best", broken)
    observation = campaign.observe(report(first))  # committed: the caller may acknowledge it
    assert stored_ids(path) == [first.experiment_id]
    assert campaign.n_observations == 1 and campaign.best is None
    with pytest.raises(Rejected, match="already reported"):
        campaign.observe(report(first, value=2.0))
    monkeypatch.setattr(campaign.planner, "best", best)
    campaign.propose(1)  # the planner learns from what is stored; the best is looked for again
    assert campaign.planner.observations[0] is observation and campaign.best is observation
    campaign.observe(report(second, value=5.0))
    assert [o.experiment_id for o in campaign.history().observations] == [first.experiment_id, second.experiment_id]
    assert campaign.best.experiment_id == second.experiment_id
    assert stored_ids(path) == [first.experiment_id, second.experiment_id]


def test_the_planner_keeps_no_copy_of_the_campaign(tmp_path):
    """What the planner learns from is the campaign's snapshot of its store, handed over for each proposal: an
    observation stored while nothing is asked is in the next proposal's history, not copied into the planner."""
    campaign = Campaign(CONFIG, tmp_path / "c.sqlite", seed=0)
    proposals = campaign.propose(2)
    campaign.observe(report(proposals[0]))
    stored = campaign.history()
    assert [o.experiment_id for o in stored.observations] == [proposals[0].experiment_id]
    assert list(stored.pending) == [proposals[1].experiment_id] and stored.ask_count == 1
    campaign.propose(1)
    assert campaign.planner.history.observations == stored.observations
    assert campaign.planner.history is not campaign.history()


def test_refused_observations_store_nothing(tmp_path):
    path = tmp_path / "c.sqlite"
    campaign = Campaign(CONFIG, path, seed=0)
    [proposal] = campaign.propose(1)
    with pytest.raises(ObservationError, match="violate the known constraint"):
        campaign.observe({**report(proposal), "params": {"x": 7.0, "solvent": "THF"}})
    with pytest.raises(Rejected, match="did not propose it"):
        campaign.observe({**report(proposal), "experiment_id": "made-up"})
    with pytest.raises(Rejected, match="needs the experiment_id"):
        campaign.observe({"params": proposal.params, "objectives": {"y": 1.0}})
    assert stored_ids(path) == [] and campaign.pending == [proposal]
    rejected = campaign.store.rejections()  # kept apart, with their reasons, for the dashboard and audits
    assert [r["experiment_id"] for r in rejected] == [proposal.experiment_id, "made-up", None]
    assert "violate the known constraint" in rejected[0]["reason"] and "did not propose" in rejected[1]["reason"]
    prior = Campaign(CONFIG, tmp_path / "prior.sqlite", seed=0, accept_unsolicited=True)
    prior.observe({"params": {"x": 1.0, "solvent": "DMF"}, "objectives": {"y": 0.3}})
    prior.observe({"experiment_id": "lab-7", "params": {"x": 2.0, "solvent": "DMF"}, "objectives": {"y": None}})
    assert prior.status()["n_observations"] == 2 and prior.status()["n_failed"] == 1


def test_the_message_is_stored_as_it_arrived(tmp_path):
    campaign = Campaign(CONFIG, tmp_path / "c.sqlite", seed=0)
    [proposal] = campaign.propose(1)
    # spacing and key order of the sender's own: kept as it arrived, not re-serialized
    text = f'{{"objectives": {{"y": 1}},   "experiment_id": "{proposal.experiment_id}", ' \
           f'"params": {json.dumps(proposal.params)}}}'
    campaign.observe(messages.parse("observation", text), raw=text)
    assert campaign.store.raw(proposal.experiment_id) == text


def test_a_restart_continues_the_campaign_exactly(tmp_path):
    straight = Campaign(CONFIG, tmp_path / "a.sqlite", seed=3)
    for proposal in straight.propose(2):
        straight.observe(report(proposal, proposal.params["x"]))
    expected = straight.propose(2)

    first = Campaign(CONFIG, tmp_path / "b.sqlite", seed=3)
    for proposal in first.propose(2):
        first.observe(report(proposal, proposal.params["x"]))
    first.close()
    resumed = Campaign(CONFIG, tmp_path / "b.sqlite")  # the seed comes from the store
    assert resumed.seed == 3 and resumed.n_observations == 2 and resumed.pending == []
    # same seed, same observations, same counters, same process: the very same computation
    assert [p.params for p in resumed.propose(2)] == [p.params for p in expected]
    resumed.close()
    again = Campaign(CONFIG, tmp_path / "b.sqlite")
    assert len(again.pending) == 2 and again.planner.ask_count == 2


def test_another_config_cannot_take_over_a_store(tmp_path):
    Campaign(CONFIG, tmp_path / "c.sqlite", seed=0).close()
    with pytest.raises(StoreError, match="belongs to a different config"):
        Campaign({**CONFIG, "constraints": []}, tmp_path / "c.sqlite")
    Campaign(CONFIG, tmp_path / "c.sqlite").close()  # the refused attempt left the store free


HOLDER = textwrap.dedent("""
    import sys
    from gryffin_ros.campaign import Campaign
    campaign = Campaign({config!r}, {path!r}, seed=0)
    print("holding", flush=True)
    sys.stdin.read()  # until the test closes stdin (or kills this process)
""")


def test_a_store_has_one_writer_and_a_killed_writer_frees_it(tmp_path):
    path = tmp_path / "c.sqlite"
    holder = subprocess.Popen([sys.executable, "-c", HOLDER.format(config=CONFIG, path=str(path))],
                              stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "holding"
        with pytest.raises(StoreError) as info:
            Campaign(CONFIG, path)
        assert f"'{path}' is in use by pid {holder.pid}" in str(info.value)
        with Campaign(CONFIG, tmp_path / "other.sqlite"):
            pass  # another file is free
    finally:
        holder.kill()
        holder.wait()
    with Campaign(CONFIG, path) as campaign:  # the operating system released the dead writer's lock
        assert campaign.seed == 0


def test_auto_published_proposals_are_handed_out_first_by_claim(tmp_path):
    campaign = Campaign(CONFIG, tmp_path / "c.sqlite", seed=0)
    published = campaign.propose(2, claimed=False)
    first = campaign.claim(1)
    second = campaign.claim(2)
    assert first == published[:1]
    assert second[0] == published[1] and second[1] not in published
    assert len(campaign.pending) == 3
    third = campaign.claim(1)
    assert third[0] not in published + second  # nothing is handed out twice
    campaign.observe(report(published[0]))
    campaign.mark_unclaimed()  # a restart announces everything owed again
    assert [p.experiment_id for p in campaign.claim(3)] == [p.experiment_id for p in campaign.pending]


def test_an_instrument_asking_again_gets_its_unreported_claims_back_and_nobody_else_does(tmp_path):
    path = tmp_path / "c.sqlite"
    ids = lambda proposals: [p.experiment_id for p in proposals]  # noqa: E731
    with Campaign(CONFIG, path, seed=0) as campaign:
        published = campaign.propose(2, claimed=False)
        a, b = campaign.claim(1, instrument="/lab/a"), campaign.claim(1, instrument="/lab/b")
        assert ids(a + b) == ids(published)  # the published batch is shared between the two
        assert campaign.claim(1, instrument="/lab/a") == a  # a lost answer: asked again, the same experiment
        more = campaign.claim(2, instrument="/lab/a")  # its own first, then a new one
        assert more[0] == a[0] and more[1].experiment_id not in ids(published)
        campaign.observe(report(a[0]))
        assert campaign.claim(1, instrument="/lab/a") == more[1:]
        anonymous = campaign.claim(1)  # a caller without a name never gets an instrument's claims
        assert anonymous[0].experiment_id not in ids(b + more)
    with Campaign(CONFIG, path) as campaign:  # a restart: the claims are stored, what nobody named is unclaimed
        campaign.mark_unclaimed()
        assert campaign.claim(1, instrument="/lab/c") == anonymous
        assert campaign.claim(1, instrument="/lab/b") == b
        assert campaign.claim(1, instrument="/lab/a") == more[1:]
        assert len(campaign.pending) == 3  # nothing was proposed for the three who asked again


def test_status_follows_the_campaign_and_fits_the_schema(tmp_path):
    campaign = Campaign({**CONFIG, "constraints": [*CONFIG["constraints"], "x < 50"]}, tmp_path / "c.sqlite",
                        seed=0)
    proposals = campaign.propose(2)
    campaign.observe(report(proposals[0], 0.2))
    campaign.observe({**report(proposals[1]), "objectives": {"y": None}})
    status = campaign.status()
    messages.check("status", status)
    assert (status["n_observations"], status["n_pending"], status["n_failed"]) == (2, 0, 1)
    assert status["best"]["experiment_id"] == proposals[0].experiment_id
    assert len(status["warnings"]) == 1 and "'x < 50' excludes no point" in status["warnings"][0]


def test_a_closed_campaign_stores_nothing_more(tmp_path):
    path = tmp_path / "c.sqlite"
    campaign = Campaign(CONFIG, path, seed=0)
    [proposal] = campaign.propose(1)
    campaign.close()
    with pytest.raises(CampaignClosed):
        campaign.observe(report(proposal))
    assert stored_ids(path) == []


def test_status_says_optimizing_while_proposing_and_a_failed_claim_keeps_the_unclaimed(tmp_path, monkeypatch):
    campaign = Campaign(CONFIG, tmp_path / "c.sqlite", seed=0)
    seen = []
    published = campaign.propose(1, claimed=False, progress=lambda *_: seen.append(campaign.status()["state"]))
    assert seen and set(seen) == {"optimizing"} and campaign.status()["state"] == "idle"

    def broken(n=None):
        raise RuntimeError("optimizer crashed")
    monkeypatch.setattr(campaign.planner, "draw", broken)
    with pytest.raises(RuntimeError):
        campaign.claim(2)  # one unclaimed, one to make: the making fails
    assert campaign.status()["state"] == "error"
    monkeypatch.undo()
    assert campaign.claim(1) == published  # still handed out first



def test_proposals_the_store_could_not_take_are_forgotten_and_drawn_again(tmp_path, monkeypatch):
    reference = Campaign(CONFIG, tmp_path / "a.sqlite", seed=5).propose(2)
    campaign = Campaign(CONFIG, tmp_path / "b.sqlite", seed=5)

    def full_disk(proposals, meta=None):
        raise OSError("disk full")
    monkeypatch.setattr(campaign.store, "add_proposals", full_disk)
    with pytest.raises(OSError):
        campaign.propose(2)
    assert campaign.pending == [] and campaign.history().ask_count == 0
    monkeypatch.undo()
    # same seed, same (restored) counters, same process: the very same computation as the reference's first ask
    assert [p.params for p in campaign.propose(2)] == [p.params for p in reference]
    campaign.close()
    with pytest.raises(CampaignClosed):
        campaign.propose(1)


def test_a_proposal_stopped_at_a_checkpoint_leaves_nothing_behind_and_the_next_draws_the_same(tmp_path):
    from gryffin_ros.planner.reporting import Cancelled

    def campaign_with_data(path):
        campaign = Campaign(CONFIG, path, seed=0)
        for i, proposal in enumerate(campaign.propose(3)):
            campaign.observe(report(proposal, float(i)))
        return campaign
    stopped, plain = campaign_with_data(tmp_path / "a.sqlite"), campaign_with_data(tmp_path / "b.sqlite")
    stages = []

    def stop_when_optimizing(stage, fraction, ready):
        stages.append(stage)
        assert 0.0 <= fraction <= 1.0
        if stage == "optimizing":
            raise Cancelled("stopped by the test")
    with pytest.raises(Cancelled):
        stopped.claim(2, progress=stop_when_optimizing)
    assert stages[0] == "models" and stages[-1] == "optimizing"
    assert stopped.pending == [] and stopped.status()["state"] == "idle"
    again, reference = stopped.propose(2), plain.propose(2)
    assert [p.params for p in again] == [p.params for p in reference]


def test_every_ask_gives_its_freed_memory_back_also_when_it_fails(tmp_path, monkeypatch):
    """glibc keeps an ask's freed matrices for reuse unless told to return them: without this, a long campaign's
    resident memory rose with its largest ask (benchmarks/soak.py)."""
    from gryffin_ros import campaign as module
    calls = []
    monkeypatch.setattr(module, "give_back_freed_memory", lambda: calls.append("trim"))
    campaign = Campaign(CONFIG, tmp_path / "c.sqlite", seed=0)
    asked = campaign.planner.draw
    monkeypatch.setattr(campaign.planner, "draw", lambda n=None: calls.append("ask") or asked(n))
    campaign.propose(2)
    assert calls == ["ask", "trim"]
    monkeypatch.setattr(campaign.planner, "draw", lambda n=None: calls.append("ask") or 1 / 0)
    with pytest.raises(ZeroDivisionError):
        campaign.propose(1)
    assert calls == ["ask", "trim", "ask", "trim"]
    campaign.close()


# ---- serving a lab: the node's policy, without ROS ----------------------------------------------------------------
def test_nothing_is_asked_before_serving_and_auto_proposals_wait_for_what_is_owed(tmp_path):
    from gryffin_ros.asks import NotServing
    campaign = Campaign(CONFIG, tmp_path / "c.sqlite", seed=0)
    with pytest.raises(NotServing, match="not active"):
        campaign.recommend(1)
    assert campaign.auto_proposals(1) == [] and campaign.pending == []
    assert campaign.serve() == []
    published = campaign.auto_proposals(2)
    assert len(published) == 2 and campaign.pending == published
    assert campaign.auto_proposals(2) == []  # owed: nothing more until they are reported
    campaign.observe(report(published[0]))
    assert campaign.auto_proposals(2) == []
    campaign.observe(report(published[1]))
    assert len(campaign.auto_proposals(2)) == 2
    # unasked proposals are what the next ask is handed first
    assert campaign.recommend(2) == campaign.pending


def test_a_failed_ask_blocks_auto_proposals_until_new_data_arrives(tmp_path, monkeypatch):
    from gryffin_ros.planner import GryffinRosError
    campaign = Campaign(CONFIG, tmp_path / "c.sqlite", seed=0)
    campaign.serve()
    asked = campaign.recommend(1)

    def broken(n=None):
        raise RuntimeError("optimizer crashed")
    monkeypatch.setattr(campaign.planner, "draw", broken)
    campaign.observe(report(asked[0]))
    with pytest.raises(GryffinRosError, match="internal error: RuntimeError"):  # a bug, said, not raised as is
        campaign.auto_proposals(1)
    assert campaign.last_error and "optimizer crashed" in campaign.last_error
    monkeypatch.undo()
    assert campaign.auto_proposals(1) == []  # blocked: asking again on the same data would fail again
    one = campaign.recommend(1)  # a lab's own ask is never blocked
    campaign.observe(report(one[0]))
    assert len(campaign.auto_proposals(1)) == 1 and campaign.last_ask_s is not None


def test_the_experiments_owed_are_announced_again_after_a_quiet_spell_only(tmp_path, monkeypatch):
    from gryffin_ros import campaign as module
    campaign = Campaign(CONFIG, tmp_path / "c.sqlite", seed=0)
    campaign.serve()
    owed = campaign.recommend(2)
    monkeypatch.setattr(module, "REMIND_AFTER_S", 3600.0)
    assert campaign.owed_after_quiet() == []  # just served: not quiet
    monkeypatch.setattr(module, "REMIND_AFTER_S", -1.0)  # any spell counts as quiet
    assert campaign.owed_after_quiet() == owed
    campaign.observe(report(owed[0]))
    assert campaign.owed_after_quiet() == owed[1:]


def test_an_ask_stops_when_its_caller_cancels_or_serving_stops_and_leaves_nothing_behind(tmp_path):
    import threading

    from gryffin_ros.asks import Stopped
    from gryffin_ros.planner.reporting import Cancelled
    campaign = Campaign(CONFIG, tmp_path / "c.sqlite", seed=0)
    campaign.serve()
    for proposal in campaign.recommend(3):
        campaign.observe(report(proposal))
    with pytest.raises(Cancelled, match="canceled by the client"):
        campaign.recommend(1, cancelled=lambda: True)
    assert campaign.pending == []

    optimizing = threading.Event()

    def progress(stage, fraction, ready):
        if stage == "optimizing":
            optimizing.set()
    outcome = []

    def ask():
        try:
            campaign.recommend(1, progress=progress)
        except Stopped as exc:
            outcome.append(str(exc))
    asker = threading.Thread(target=ask)
    asker.start()
    assert optimizing.wait(60)
    campaign.stop_serving("deactivated by the test")  # returns once the running ask has ended
    assert campaign.asks.settled() and outcome == ["deactivated by the test"]
    asker.join(10)
    assert campaign.pending == [] and campaign.status()["state"] == "idle"
    assert campaign.serve() == [] and len(campaign.recommend(1)) == 1  # serving again


def test_an_ask_queued_behind_another_waits_and_can_be_stopped_before_it_starts(tmp_path):
    import threading

    from gryffin_ros.asks import AskQueue, Stopped
    queue = AskQueue()
    queue.open()
    release, running = threading.Event(), threading.Event()

    def first(checkpoint):
        running.set()
        assert release.wait(60)
        return "first"
    heard, outcome = [], {}

    def run(name, make, **kw):
        try:
            outcome[name] = queue.run(make, **kw)
        except Stopped as exc:
            outcome[name] = exc
    t1 = threading.Thread(target=run, args=("first", first))
    t1.start()
    assert running.wait(60)
    waiting = threading.Event()

    def progress(stage, fraction, ready):
        heard.append(stage)
        waiting.set()
    t2 = threading.Thread(target=run, args=("second", lambda checkpoint: "second"), kwargs={"progress": progress})
    t2.start()
    assert waiting.wait(60) and set(heard) == {"waiting"}
    queue.close("stopped by the test", wait=False)
    t2.join(10)
    assert isinstance(outcome["second"], Stopped)  # never started
    release.set()
    t1.join(10)
    assert outcome["first"] == "first" and queue.settled()
    queue.shutdown()


def test_recent_rejections_are_read_from_the_store(tmp_path):
    campaign = Campaign(CONFIG, tmp_path / "c.sqlite", seed=0)
    campaign.reject("not JSON", "{", None)
    with pytest.raises(Rejected):
        campaign.observe({"experiment_id": "nope", "params": {"x": 1.0, "solvent": "THF"}, "objectives": {"y": 1}})
    assert campaign.recent_rejections(60.0)[0] == "not JSON" and len(campaign.recent_rejections(60.0)) == 2
    assert campaign.recent_rejections(-60.0) == []  # a window ending a minute ago holds none of them
    campaign.close()
    assert campaign.recent_rejections(60.0) == []


MOLECULES = {"name": "ligands",
             "parameters": [{"name": "ligand", "type": "categorical",
                             "options": {"PPh3": "c1ccc(P(c2ccccc2)c2ccccc2)cc1", "PMe3": "CP(C)C",
                                         "pyridine": "c1ccncc1"}},
                            {"name": "x", "type": "continuous", "low": 0.0, "high": 1.0}],
             "objectives": [{"name": "y", "goal": "max"}],
             "constraints": ["has_substructure(ligand, 'P') and weight(ligand) < 300"]}


def test_a_restarted_campaign_takes_molecule_descriptors_from_its_store_without_rdkit(tmp_path, monkeypatch):
    pytest.importorskip("rdkit")
    path = tmp_path / "c.sqlite"
    with Campaign(MOLECULES, path, seed=0) as campaign:
        descriptors = campaign.config.space.parameters[0].descriptors
        for proposal in campaign.propose(2):
            campaign.observe(report(proposal))
    monkeypatch.setitem(sys.modules, "rdkit", None)  # RDKit gone: the restart must not need it
    with Campaign(MOLECULES, path) as restarted:
        ligand = restarted.config.space.parameters[0]
        assert (ligand.descriptors == descriptors).all() and ligand.substructures["P"]["pyridine"] is False
        assert restarted.n_observations == 2
        (proposal,) = restarted.propose(1)
        assert proposal.params["ligand"] in ("PPh3", "PMe3")
    with pytest.raises(ConfigError, match=r"pip install gryffin_ros\[molecules\]"):
        Campaign(MOLECULES, tmp_path / "new.sqlite")  # a new store has nothing kept: RDKit is really unavailable


def test_a_restarted_campaign_reads_its_sdf_options_from_its_store_without_rdkit(tmp_path, monkeypatch):
    chem = pytest.importorskip("rdkit.Chem")
    writer = chem.SDWriter(str(tmp_path / "ligands.sdf"))
    for name, smiles in (("PPh3", "c1ccc(P(c2ccccc2)c2ccccc2)cc1"), ("PMe3", "CP(C)C"), ("pyridine", "c1ccncc1")):
        molecule = chem.MolFromSmiles(smiles)
        molecule.SetProp("_Name", name)
        writer.write(molecule)
    writer.close()
    config = {**MOLECULES, "parameters": [{"name": "ligand", "type": "categorical", "options": "ligands.sdf"},
                                          MOLECULES["parameters"][1]]}
    (tmp_path / "c.yaml").write_text(json.dumps(config))  # JSON is YAML; the SDF is named relative to it
    with Campaign(tmp_path / "c.yaml", tmp_path / "c.sqlite", seed=0) as campaign:
        smiles = campaign.config.space.parameters[0].smiles
        campaign.observe(report(campaign.propose(1)[0]))
    monkeypatch.setitem(sys.modules, "rdkit", None)
    with Campaign(tmp_path / "c.yaml", tmp_path / "c.sqlite") as restarted:
        assert restarted.config.space.parameters[0].smiles == smiles and list(smiles) == ["PPh3", "PMe3", "pyridine"]
        assert restarted.n_observations == 1
    with (tmp_path / "ligands.sdf").open("a") as handle:  # another file: read anew, which needs RDKit
        handle.write("\n")
    with pytest.raises(ConfigError, match=r"pip install gryffin_ros\[molecules\]"):
        Campaign(tmp_path / "c.yaml", tmp_path / "c.sqlite")
