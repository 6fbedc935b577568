"""The dashboard's server over real HTTP on loopback: pages, the offline plotting library, read-only."""

import json
import sys
import urllib.error
import urllib.request

import pytest

from gryffin_ros.campaign import Campaign
from gryffin_ros.dashboard import start


def get(url):
    with urllib.request.urlopen(url, timeout=60) as response:
        return response.status, response.headers.get("Content-Type"), response.read()


@pytest.fixture
def server(campaign):
    server = start(campaign.store.path, port=0)
    yield server
    server.close()


def test_the_page_and_everything_it_loads_come_from_this_server(server):
    assert server.server_address[0] == "127.0.0.1" and server.url.startswith("http://127.0.0.1:")
    status, kind, page = get(server.url)
    assert status == 200 and kind.startswith("text/html")
    for script in (b'src="plotly.min.js"', b'src="dashboard.js"', b'href="dashboard.css"'):
        assert script in page
    assert b"http://" not in page and b"https://" not in page  # no CDN: the page works offline
    for path in ("plotly.min.js", "dashboard.js", "dashboard.css"):
        assert get(server.url + path)[0] == 200
    assert len(get(server.url + "plotly.min.js")[2]) > 1_000_000  # the real library, not a stub


def test_the_api_answers_json_and_refuses_what_it_does_not_serve(server):
    data = json.loads(get(server.url + "api/campaign")[2])
    assert data["campaign"] == "board_test" and len(data["experiments"]) == 5
    region = json.loads(get(server.url + "api/feasible?x=x&y=solvent")[2])
    assert region["y"]["values"] == ["THF", "DMF"]
    with pytest.raises(urllib.error.HTTPError) as bad:
        get(server.url + "api/feasible?x=x&y=x")
    assert bad.value.code == 400 and "two different parameters" in json.loads(bad.value.read())["error"]
    with pytest.raises(urllib.error.HTTPError) as missing:
        get(server.url + "nowhere")
    assert missing.value.code == 404
    request = urllib.request.Request(server.url + "api/campaign", data=b"{}", method="POST")
    with pytest.raises(urllib.error.HTTPError) as post:
        urllib.request.urlopen(request, timeout=60)
    assert post.value.code == 405  # read-only


def test_requests_addressed_to_another_name_are_refused(server):
    """A page that rebinds its own host name to 127.0.0.1 cannot read the campaign."""
    request = urllib.request.Request(server.url + "api/campaign", headers={"Host": "attacker.example:80"})
    with pytest.raises(urllib.error.HTTPError) as refused:
        urllib.request.urlopen(request, timeout=60)
    assert refused.value.code == 403
    request = urllib.request.Request(server.url + "api/campaign", headers={"Host": f"localhost:{server.server_port}"})
    assert urllib.request.urlopen(request, timeout=60).status == 200


def test_a_port_that_cannot_be_served_is_a_clear_error(campaign, server):
    from gryffin_ros.planner import GryffinRosError
    with pytest.raises(GryffinRosError, match="cannot serve on 127.0.0.1"):
        start(campaign.store.path, port=server.server_port)  # taken
    with pytest.raises(GryffinRosError, match="port must be 0..65535"):
        start(campaign.store.path, port=70000)


MOLECULES = {"name": "solvents",
             "parameters": [{"name": "solvent", "type": "categorical",
                             "options": {"toluene": "Cc1ccccc1", "DMF": "CN(C)C=O", "<b>": "CO"}},
                            {"name": "T", "type": "continuous", "low": 20.0, "high": 100.0}],
             "objectives": [{"name": "y", "goal": "max"}]}


@pytest.fixture
def molecule_server(tmp_path):
    pytest.importorskip("rdkit")
    with Campaign(MOLECULES, tmp_path / "m.sqlite", seed=0) as campaign:
        (proposal,) = campaign.propose(1)
        campaign.observe({"experiment_id": proposal.experiment_id, "params": proposal.params,
                          "objectives": {"y": 1.0}})
        campaign.propose(1)
    server = start(tmp_path / "m.sqlite", port=0)
    yield server
    server.close()


def test_the_molecules_of_the_config_are_drawn_and_nothing_else(molecule_server, monkeypatch):
    url = molecule_server.url
    data = json.loads(get(url + "api/campaign")[2])
    assert data["parameters"][0]["smiles"] == MOLECULES["parameters"][0]["options"]
    status, kind, svg = get(url + "api/molecule.svg?parameter=solvent&option=DMF")
    assert status == 200 and kind == "image/svg+xml" and svg.lstrip().startswith(b"<?xml") and b"<svg" in svg
    assert get(url + "api/molecule.svg?parameter=solvent&option=%3Cb%3E")[0] == 200  # a name that needs quoting
    with pytest.raises(urllib.error.HTTPError) as other:  # only the config's molecules: no SMILES from the URL
        get(url + "api/molecule.svg?parameter=solvent&option=CCO")
    assert other.value.code == 400 and "no molecule of 'solvent'" in json.loads(other.value.read())["error"]
    monkeypatch.setitem(sys.modules, "rdkit", None)  # without RDKit the page keeps the SMILES and draws nothing
    with pytest.raises(urllib.error.HTTPError) as missing:
        get(url + "api/molecule.svg?parameter=solvent&option=toluene")
    assert missing.value.code == 501 and "gryffin_ros[molecules]" in json.loads(missing.value.read())["error"]
