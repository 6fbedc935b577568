"""The dashboard in a real browser: Debian's headless Chromium driven by selenium through Debian's chromedriver,
against a store a short campaign wrote; the page follows the store live."""

import shutil
import time

import pytest

from gryffin_ros.campaign import Campaign
from gryffin_ros.dashboard import start

from .conftest import add_one

CHROMIUM = shutil.which("chromium")
CHROMEDRIVER = shutil.which("chromedriver")
webdriver = pytest.importorskip("selenium.webdriver", reason="selenium is not installed (make installs it)")
pytestmark = [pytest.mark.browser, pytest.mark.skipif(
    CHROMIUM is None or CHROMEDRIVER is None,
    reason="Debian's chromium and chromium-driver are not installed (as root: apt-get install chromium "
           "chromium-driver; .ci/run does)")]
# Deadlines only catch hangs: the page polls every 2 s and draws in well under a second here.
HANG_S = 120


@pytest.fixture
def browser(tmp_path):
    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    for flag in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update", "--disable-sync",
                 "--disable-dev-shm-usage", f"--user-data-dir={tmp_path / 'chromium'}", "--window-size=1400,2000"):
        options.add_argument(flag)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(options=options, service=webdriver.ChromeService(executable_path=CHROMEDRIVER))
    yield driver
    driver.quit()


def rows(driver):
    return driver.execute_script("return document.querySelectorAll('#experiments tbody tr').length")


def wait_for(condition, timeout=HANG_S):
    deadline = time.monotonic() + timeout
    while not condition():
        assert time.monotonic() < deadline, "the page did not get there"
        time.sleep(0.1)


def test_the_page_shows_the_store_and_follows_it_live(campaign, browser, tmp_path):
    server = start(campaign.store.path, port=0)
    try:
        browser.get(server.url)
        wait_for(lambda: rows(browser) == 5)
        summary = browser.find_element("id", "summary").text
        assert "5 experiments" in summary and "1 failed" in summary and "1 pending" in summary
        assert "1 rejected" in summary
        headers = [th.text for th in browser.find_elements("css selector", "#experiments th")]
        assert "x (mL)" in headers and "y (%)" in " ".join(headers) and "surrogate" in headers
        # the plots were drawn by plotly (served by the dashboard itself; a graph div holds its traces in `data`),
        # the feasible region shaded under the experiments
        wait_for(lambda: browser.execute_script(
            "const g = document.getElementById('pair'); return !!g.data && g.data.some(t => t.type === 'heatmap')"))
        assert browser.execute_script("return document.getElementById('best-y').data.length") >= 2
        assert browser.execute_script("return document.getElementById('best-cost').data.length") >= 2
        errors = [entry for entry in browser.get_log("browser") if entry["level"] == "SEVERE"]
        assert errors == []

        add_one(campaign)  # the campaign goes on: the page shows it without a reload
        added = time.monotonic()
        wait_for(lambda: rows(browser) == 6)
        print(f"page updated {time.monotonic() - added:.1f} s after the observation was stored")
        browser.find_element("css selector", "#experiments th[data-key='seq']").click()  # sort descending
        wait_for(lambda: browser.execute_script(
            "return document.querySelector('#experiments tbody tr td').textContent") == "6")
        browser.save_screenshot(str(tmp_path / "dashboard.png"))
    finally:
        server.close()


def test_the_page_shows_the_smiles_and_draws_the_pending_molecules(browser, tmp_path):
    pytest.importorskip("rdkit")
    config = {"name": "m", "parameters": [{"name": "solvent", "type": "categorical",
                                           "options": {"toluene": "Cc1ccccc1", "DMF": "CN(C)C=O"}},
                                          {"name": "T", "type": "continuous", "low": 20.0, "high": 100.0}],
              "objectives": [{"name": "y", "goal": "max"}]}
    with Campaign(config, tmp_path / "m.sqlite", seed=0) as campaign:
        (proposal,) = campaign.propose(1)
        campaign.observe({"experiment_id": proposal.experiment_id, "params": proposal.params, "objectives": {"y": 1}})
        (pending,) = campaign.propose(1)
    server = start(tmp_path / "m.sqlite", port=0)
    try:
        browser.get(server.url)
        wait_for(lambda: rows(browser) == 1)
        headers = [th.text for th in browser.find_elements("css selector", "#experiments th")]
        assert headers[headers.index("solvent") + 1] == "solvent SMILES"
        shown = browser.find_element("css selector", "#experiments tbody tr").text
        assert config["parameters"][0]["options"][proposal.params["solvent"]] in shown
        # the pending proposal's molecule, drawn by the server: an image that loaded
        wait_for(lambda: browser.execute_script(
            "const i = document.querySelector('#pending td.molecule img'); return !!i && i.complete && "
            "i.naturalWidth > 0"))
        alt = browser.execute_script("return document.querySelector('#pending td.molecule img').alt")
        assert alt == pending.params["solvent"]
        assert [e for e in browser.get_log("browser") if e["level"] == "SEVERE"] == []
    finally:
        server.close()
