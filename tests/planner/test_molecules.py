"""Molecules as categorical options: SMILES in the config or a file, RDKit descriptors, constraints on structure."""

import sys

import numpy as np
import pytest

from gryffin_ros.planner import ConfigError, ExhaustedSpaceError, Expression, Planner, load_config
from gryffin_ros.planner.molecules import CATALOG, DEFAULT_SET, MoleculeCache

LIGANDS = {"PPh3": "c1ccc(P(c2ccccc2)c2ccccc2)cc1", "PMe3": "CP(C)C",
           "dppe": "c1ccc(P(CCP(c2ccccc2)c2ccccc2)c2ccccc2)cc1", "nitro": "O=[N+]([O-])c1ccc(P(C)C)cc1",
           "pyridine": "c1ccncc1"}


def config(constraints=(), **ligand):
    return {"parameters": [{"name": "ligand", "type": "categorical", "options": dict(LIGANDS), **ligand},
                           {"name": "loading", "type": "continuous", "low": 1.0, "high": 10.0}],
            "objectives": [{"name": "y", "goal": "max"}], "constraints": list(constraints)}


def ligand_parameter(cfg):
    return load_config(cfg).space.parameters[0]


def allowed_options(text, cfg=None):
    """The options of `ligand` a constraint allows (at loading 1)."""
    loaded = load_config(cfg or config([text]))
    parameters = {p.name: p for p in loaded.space.parameters}
    options = list(LIGANDS)
    mask = Expression(text, parameters, parameters).evaluate({"ligand": np.array(options, dtype=object),
                                                              "loading": np.ones(len(options))})
    return {o for o, keep in zip(options, mask) if keep}


def test_smiles_options_get_the_default_descriptors_computed_by_rdkit():
    pytest.importorskip("rdkit")
    ligand = ligand_parameter(config())
    assert ligand.options == tuple(LIGANDS) and ligand.smiles == LIGANDS
    assert ligand.descriptors.shape == (5, len(DEFAULT_SET))
    assert ligand.descriptors.min() == 0.0 and ligand.descriptors.max() == 1.0  # rescaled per column, as given ones
    weight = ligand.named_descriptors["weight"]
    assert weight["PMe3"] == pytest.approx(76.08, abs=0.01) and weight["PPh3"] == pytest.approx(262.29, abs=0.01)
    assert ligand.named_descriptors["hba"]["pyridine"] == 1.0
    assert set(CATALOG) <= set(ligand.named_descriptors)  # every property usable in constraints


def test_user_descriptors_are_combined_with_the_computed_ones():
    pytest.importorskip("rdkit")
    cone = {"PPh3": [145], "PMe3": [118], "dppe": [125], "nitro": [122], "pyridine": [100]}
    ligand = ligand_parameter(config(descriptors=cone, descriptor_names=["cone_angle"]))
    assert ligand.descriptors.shape == (5, 1 + len(DEFAULT_SET))
    assert ligand.descriptors[:, 0].tolist() == pytest.approx([1.0, 18 / 45, 25 / 45, 22 / 45, 0.0])
    assert ligand.named_descriptors["cone_angle"]["PMe3"] == 118.0
    unnamed = ligand_parameter(config(descriptors=cone, molecular_descriptors=["tpsa"]))
    assert unnamed.descriptors.shape == (5, 2)


@pytest.mark.parametrize("chosen, columns", [("lipinski", 4), ("all", len(CATALOG)), (["rings", "charge"], 2)])
def test_a_named_descriptor_set_or_a_list_chooses_the_columns(chosen, columns):
    pytest.importorskip("rdkit")
    assert ligand_parameter(config(molecular_descriptors=chosen)).descriptors.shape == (5, columns)


def test_no_computed_descriptors_leaves_the_properties_for_constraints():
    pytest.importorskip("rdkit")
    ligand = ligand_parameter(config(["weight(ligand) < 300"], molecular_descriptors="none"))
    assert ligand.descriptors is None and ligand.named_descriptors["weight"]["PPh3"] > 0


@pytest.mark.parametrize("ligand, message", [
    ({"molecular_descriptors": "lipinsky"}, "no descriptor set.*did you mean 'lipinski'"),
    ({"molecular_descriptors": ["weigth"]}, "unknown molecular descriptor 'weigth'.*did you mean 'weight'"),
    ({"molecular_descriptors": ["tpsa", "tpsa"]}, "duplicates"),
    ({"molecular_descriptors": 3}, "a set name or a list"),
    ({"descriptors": {o: [1.0] for o in LIGANDS}, "descriptor_names": ["weight"]}, "computed from the SMILES"),
])
def test_bad_molecular_descriptor_choices_are_refused(ligand, message):
    pytest.importorskip("rdkit")
    with pytest.raises(ConfigError, match=message):
        load_config(config(**ligand))


def test_molecular_descriptors_need_smiles_options():
    cfg = {"parameters": [{"name": "s", "type": "categorical", "options": ["a", "b"],
                           "molecular_descriptors": "default"}]}
    with pytest.raises(ConfigError, match="'molecular_descriptors' needs the options as SMILES"):
        load_config(cfg)


@pytest.mark.parametrize("smiles, detail", [("C1CC(", "position 5"), ("CN(C)(C)(C)C", "valence"),
                                            ("Cc1ccccc", "unclosed ring"), ("", "SMILES string")])
def test_an_invalid_smiles_is_refused_naming_the_option_and_what_rdkit_reports(smiles, detail):
    pytest.importorskip("rdkit")
    cfg = config()
    cfg["parameters"][0]["options"]["broken"] = smiles
    with pytest.raises(ConfigError, match=f"parameter 'ligand'.*'broken'.*{detail}"):
        load_config(cfg)


def test_an_invalid_smarts_is_refused_naming_the_constraint_and_position():
    pytest.importorskip("rdkit")
    with pytest.raises(ConfigError, match=r"has_substructure\(ligand.*'\[N\+\]\(=O' is not a valid SMARTS.*position 5"):
        load_config(config(["has_substructure(ligand, '[N+](=O') == False"]))


def test_a_smiles_config_without_rdkit_is_refused_naming_the_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "rdkit", None)  # `import rdkit` raises ImportError, as when it is not installed
    with pytest.raises(ConfigError, match=r"parameter 'ligand' \(options given as SMILES\) needs RDKit, which is "
                                          r"not installed: pip install gryffin_ros\[molecules\]"):
        load_config(config())


def test_values_in_the_cache_are_not_computed_again(monkeypatch):
    pytest.importorskip("rdkit")
    cache = MoleculeCache()
    first = ligand_parameter(config())  # without cache
    load_config(config(["has_substructure(ligand, 'P') == True"]), molecule_cache=cache)
    assert len(cache.computed) == 5 * (len(CATALOG) + 1)
    monkeypatch.setitem(sys.modules, "rdkit", None)
    again = load_config(config(["has_substructure(ligand, 'P') == True"]),
                        molecule_cache=MoleculeCache(cache.values)).space.parameters[0]
    np.testing.assert_array_equal(again.descriptors, first.descriptors)
    assert again.substructures == {"P": {"PPh3": True, "PMe3": True, "dppe": True, "nitro": True, "pyridine": False}}


@pytest.mark.parametrize("text, allowed", [
    ("weight(ligand) < 270", {"PPh3", "PMe3", "nitro", "pyridine"}),
    ("has_substructure(ligand, '[N+](=O)[O-]') == False", {"PPh3", "PMe3", "dppe", "pyridine"}),
    ("not has_substructure(ligand, 'P')", {"pyridine"}),
    ("rings(ligand) <= 1", {"PMe3", "nitro", "pyridine"}),
    ("hbd(ligand) == 0 and aromatic_rings(ligand) >= 3", {"PPh3", "dppe"}),
    ("weight(ligand) * loading < 100", {"PMe3", "pyridine"}),
])
def test_constraints_on_molecules_keep_exactly_the_options_that_satisfy_them(text, allowed):
    pytest.importorskip("rdkit")
    assert allowed_options(text) == allowed


def test_proposals_keep_to_a_structure_constraint_until_the_allowed_options_are_used_up():
    pytest.importorskip("rdkit")
    cfg = {"parameters": [{"name": "ligand", "type": "categorical", "options": dict(LIGANDS)}],
           "objectives": [{"name": "y", "goal": "max"}],
           "constraints": ["has_substructure(ligand, 'c1ccccc1') and weight(ligand) < 500"]}
    planner = Planner(cfg, seed=0)
    seen = []
    for _ in range(3):
        (proposal,) = planner.ask()
        seen.append(proposal.params["ligand"])
        planner.tell({**proposal.params, "y": 1.0, "experiment_id": proposal.experiment_id})
    assert sorted(seen) == ["PPh3", "dppe", "nitro"]
    with pytest.raises(ExhaustedSpaceError):
        planner.ask()


def test_a_molecule_constraint_with_a_user_descriptor_of_another_parameter():
    pytest.importorskip("rdkit")
    cfg = config(["T < boiling_point(solvent) - 10 and weight(ligand) < 500"])
    cfg["parameters"].append({"name": "solvent", "type": "categorical", "options": ["toluene", "THF"],
                              "descriptors": {"toluene": [111], "THF": [66]}, "descriptor_names": ["boiling_point"]})
    cfg["parameters"].append({"name": "T", "type": "continuous", "low": 20, "high": 150})
    planner = Planner(cfg, seed=1)
    for _ in range(4):
        (proposal,) = planner.ask()
        limit = {"toluene": 101, "THF": 56}[proposal.params["solvent"]]
        assert proposal.params["T"] < limit
        planner.tell({**proposal.params, "y": proposal.params["T"], "experiment_id": proposal.experiment_id})


def test_a_constraint_that_excludes_no_molecule_is_warned():
    pytest.importorskip("rdkit")
    planner = Planner(config(["weight(ligand) < 5000"]), seed=0)
    assert any("weight(ligand) < 5000" in w and "excludes no point" in w for w in planner.constraint_warnings)


@pytest.mark.parametrize("text, message", [
    ("has_substructure(loading, 'C')", "has_substructure\\(\\) of 'loading', whose options are not given as SMILES"),
    ("has_substructure(ligand, 3)", "has_substructure\\(\\) with anything but a parameter whose options are SMILES"),
    ("has_substructure(ligand)", "has_substructure\\(\\) with anything but"),
    ("has_substructure(ligand, 'P', 'C')", "has_substructure\\(\\) with anything but"),
    ("wieght(ligand) < 3", "no descriptor named 'wieght'.*did you mean 'weight'"),
    ("wieght(x) < 3", "calling 'wieght'.*did you mean 'weight'"),
    ("weight(loading) < 3", "weight\\(\\) of anything but one categorical parameter"),
    ("weight(solvent) < 3", "computed for options given as SMILES"),
    ("weight(ligand, ligand) < 3", "weight\\(\\) of anything but one categorical parameter"),
])
def test_molecule_functions_with_wrong_arguments_are_refused(text, message):
    pytest.importorskip("rdkit")
    cfg = config([text])
    cfg["parameters"].append({"name": "solvent", "type": "categorical", "options": ["toluene", "THF"]})
    with pytest.raises(ConfigError, match=message):
        Planner(cfg, seed=0)


def test_options_from_a_csv_file_next_to_the_config(tmp_path):
    pytest.importorskip("rdkit")
    (tmp_path / "ligands.csv").write_text("Name,SMILES,supplier\nPMe3,CP(C)C,x\npyridine,c1ccncc1,y\n")
    cfg = {"parameters": [{"name": "ligand", "type": "categorical", "options": "ligands.csv"}],
           "constraints": ["weight(ligand) < 78"]}
    path = tmp_path / "config.yaml"
    path.write_text(__import__("yaml").safe_dump(cfg))
    loaded = load_config(path)
    assert loaded.space.parameters[0].smiles == {"PMe3": "CP(C)C", "pyridine": "c1ccncc1"}
    # the config's hash and the stored config hold the molecules themselves, not the file's name
    assert loaded.raw["parameters"][0]["options"] == {"PMe3": "CP(C)C", "pyridine": "c1ccncc1"}


@pytest.mark.parametrize("text, message", [("name,structure\na,C\n", "columns 'name' and 'smiles'"),
                                           ("name,smiles\na,C\na,CC\n", "line 3: option 'a' is listed twice")])
def test_a_bad_csv_of_molecules_is_refused(tmp_path, text, message):
    (tmp_path / "m.csv").write_text(text)
    cfg = {"parameters": [{"name": "m", "type": "categorical", "options": str(tmp_path / "m.csv")}]}
    with pytest.raises(ConfigError, match=message):
        load_config(cfg)


def test_options_from_an_sdf_file(tmp_path):
    chem = pytest.importorskip("rdkit.Chem")
    writer = chem.SDWriter(str(tmp_path / "m.sdf"))
    for name, smiles in (("methanol", "CO"), ("benzene", "c1ccccc1")):
        mol = chem.MolFromSmiles(smiles)
        mol.SetProp("_Name", name)
        writer.write(mol)
    writer.close()
    cfg = {"parameters": [{"name": "m", "type": "categorical", "options": str(tmp_path / "m.sdf")}]}
    ligand = load_config(cfg).space.parameters[0]
    assert ligand.smiles == {"methanol": "CO", "benzene": "c1ccccc1"}
    assert ligand.named_descriptors["aromatic_rings"] == {"methanol": 0.0, "benzene": 1.0}


def test_molecules_the_descriptors_cannot_tell_apart_are_warned_about(caplog):
    pytest.importorskip("rdkit")
    isomers = {"o-xylene": "Cc1ccccc1C", "p-xylene": "Cc1ccc(C)cc1", "toluene": "Cc1ccccc1"}
    cfg = {"parameters": [{"name": "solvent", "type": "categorical", "options": isomers}]}
    with caplog.at_level("WARNING"):
        load_config(cfg)
    assert "identical descriptors" in caplog.text and "o-xylene, p-xylene" in caplog.text
    assert "toluene" not in caplog.text


def test_computed_descriptors_are_learned_from_like_given_ones():
    pytest.importorskip("rdkit")
    cfg = {"parameters": [{"name": "ligand", "type": "categorical", "options": dict(LIGANDS)}],
           "objectives": [{"name": "y", "goal": "max"}], "general": {"auto_desc_gen": True}}
    planner = Planner(cfg, seed=0)
    weight = load_config(cfg).space.parameters[0].named_descriptors["weight"]
    for _ in range(4):
        (proposal,) = planner.ask()
        planner.tell({**proposal.params, "y": weight[proposal.params["ligand"]],
                      "experiment_id": proposal.experiment_id})
    relevance = planner.descriptor_summary()["ligand"]["objective"]["relevance"]
    assert len(relevance) == len(DEFAULT_SET) and sum(relevance) == pytest.approx(1.0, abs=1e-3)
