"""Molecules as the options of categorical parameters: SMILES from the config or a CSV/SDF file, their descriptors and
substructure matches computed once by RDKit (the optional extra `molecules`) and cached, for the models and constraints.
"""

from __future__ import annotations

import ast
import csv
import hashlib
import re
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .errors import ConfigError
from .suggest import suggestion

EXTRA = "pip install gryffin_ros[molecules]"
SUBSTRUCTURE = "has_substructure"  # has_substructure(parameter, "SMARTS") in constraint expressions

# name: (RDKit function, what it is). Every one is computed for every molecule (a few ms per molecule), so each can be
# used in a constraint, `weight(ligand) < 500`, whether or not the models use it.
CATALOG: dict[str, tuple[str, str]] = {
    "weight": ("Descriptors.MolWt", "molecular weight (g/mol)"),
    "logp": ("Crippen.MolLogP", "Wildman-Crippen logP"),
    "tpsa": ("rdMolDescriptors.CalcTPSA", "topological polar surface area (A^2)"),
    "hbd": ("Lipinski.NumHDonors", "hydrogen-bond donors"),
    "hba": ("Lipinski.NumHAcceptors", "hydrogen-bond acceptors"),
    "rotatable_bonds": ("Lipinski.NumRotatableBonds", "rotatable bonds"),
    "aromatic_rings": ("rdMolDescriptors.CalcNumAromaticRings", "aromatic rings"),
    "fraction_sp3": ("rdMolDescriptors.CalcFractionCSP3", "fraction of sp3 carbons"),
    "rings": ("rdMolDescriptors.CalcNumRings", "rings (SSSR)"),
    "heavy_atoms": ("Lipinski.HeavyAtomCount", "heavy atoms"),
    "heteroatoms": ("rdMolDescriptors.CalcNumHeteroatoms", "atoms other than C and H"),
    "molar_refractivity": ("Crippen.MolMR", "Wildman-Crippen molar refractivity"),
    "charge": ("Chem.GetFormalCharge", "net formal charge"),
}
# A few descriptors a handful of experiments can weigh: size, polarity, hydrogen bonding, flexibility, aromaticity.
DEFAULT_SET = ("weight", "logp", "tpsa", "hbd", "hba", "rotatable_bonds", "aromatic_rings", "fraction_sp3")
DESCRIPTOR_SETS: dict[str, tuple[str, ...]] = {
    "default": DEFAULT_SET, "lipinski": ("weight", "logp", "hbd", "hba"), "all": tuple(CATALOG), "none": (),
}


@dataclass(frozen=True)
class Molecules:
    """A molecular parameter's options and what was computed for them."""

    smiles: dict[str, str]  # option -> SMILES
    columns: tuple[str, ...]  # the computed descriptors the models use, in this order
    properties: dict[str, dict[str, float]]  # every CATALOG property: name -> option -> value
    substructures: dict[str, dict[str, bool]]  # SMARTS used by the constraints -> option -> match


class MoleculeCache:
    """Values computed by RDKit, by (SMILES, feature): a CATALOG name or `smarts:PATTERN`. `computed` holds those
    computed since it was made (what a campaign adds to its store)."""

    def __init__(self, values: Mapping[tuple[str, str], float] | None = None):
        self.values: dict[tuple[str, str], float] = dict(values or {})
        self.computed: dict[tuple[str, str], float] = {}

    def __contains__(self, key: tuple[str, str]) -> bool:
        return key in self.values

    def __getitem__(self, key: tuple[str, str]) -> float:
        return self.values[key]

    def put(self, key: tuple[str, str], value: float) -> None:
        self.values[key] = self.computed[key] = float(value)

    # An SDF file's molecules, by the digest of its bytes: (SMILES, "sdf:DIGEST:NAME") -> the record's position, so
    # that a campaign restarted from its store reads its SDF options without RDKit.
    def sdf(self, digest: str) -> dict[str, str] | None:
        """The option -> SMILES of the SDF file of this digest, in file order, or None when it was never read."""
        prefix = f"sdf:{digest}:"
        found = sorted((position, feature[len(prefix):], smiles) for (smiles, feature), position in self.values.items()
                       if feature.startswith(prefix))
        return {name: smiles for _, name, smiles in found} or None

    def put_sdf(self, digest: str, options: Mapping[str, str]) -> None:
        for position, (name, smiles) in enumerate(options.items()):
            self.put((smiles, f"sdf:{digest}:{name}"), position)


def rdkit(why: str) -> Any:
    """The `rdkit.Chem` module, or a ConfigError naming the extra to install."""
    try:
        from rdkit import Chem
    except ImportError:
        raise ConfigError(f"{why} needs RDKit, which is not installed: {EXTRA}") from None
    return Chem


def _rdkit_errors(parse: Callable[[], Any]) -> tuple[Any, str]:
    """Run an RDKit parser, returning its result and what RDKit reported (one line, position included)."""
    from rdkit import rdBase
    capture = getattr(rdBase, "CaptureErrorLog", None)
    if capture is None:  # RDKit before 2025: its message goes to the log
        return parse(), ""
    with capture() as log:
        result = parse()
    lines = [re.sub(r"^\[[0-9:]+\]\s*", "", line).strip() for line in str(log.messages).splitlines()]
    position = next((m.group(0) for line in lines if (m := re.search(r"position \d+", line))), None)
    reasons = [line for line in lines if line and "check for mistakes" not in line and not re.fullmatch(r"[~^ ]+", line)
               and not line.startswith(("SMILES Parse Error: Failed parsing", "SMARTS Parse Error: Failed parsing"))]
    reason = reasons[0] if reasons else ""
    if position:
        reason = f"{reason} (at {position})" if reason else f"at {position}"
    return result, reason


def parse_smiles(smiles: str, where: str) -> Any:
    """An RDKit molecule from a SMILES; a ConfigError saying where and what RDKit reports when it is not valid."""
    chem = rdkit(where)
    mol, reason = _rdkit_errors(lambda: chem.MolFromSmiles(smiles))
    if mol is None:
        raise ConfigError(f"{where}: {smiles!r} is not a valid SMILES" + (f": {reason}" if reason else ""))
    return mol


def parse_smarts(smarts: str, where: str) -> Any:
    chem = rdkit(where)
    pattern, reason = _rdkit_errors(lambda: chem.MolFromSmarts(smarts))
    if pattern is None:
        raise ConfigError(f"{where}: {smarts!r} is not a valid SMARTS" + (f": {reason}" if reason else ""))
    return pattern


def properties_of(mol: Any) -> dict[str, float]:
    """Every CATALOG property of one RDKit molecule."""
    from rdkit import Chem
    from rdkit.Chem import Crippen, Descriptors, Lipinski, rdMolDescriptors
    modules = {"Chem": Chem, "Crippen": Crippen, "Descriptors": Descriptors, "Lipinski": Lipinski,
               "rdMolDescriptors": rdMolDescriptors}
    out = {}
    for name, (function, _) in CATALOG.items():
        module, attribute = function.split(".")
        out[name] = float(getattr(modules[module], attribute)(mol))
    return out


def smiles_options(spec: Mapping[str, Any], base_dir: Path | None, cache: MoleculeCache | None = None
                   ) -> dict[str, str] | None:
    """A categorical parameter's options as option -> SMILES (given as a mapping, or a CSV/SDF file name), or None
    when they are plain names. An SDF file read once is kept in `cache` by the digest of its bytes."""
    options = spec.get("options")
    where = f"parameter '{spec.get('name')}'"
    if isinstance(options, str):
        path = Path(options) if base_dir is None or Path(options).is_absolute() else base_dir / options
        options = _read_sdf(path, where, cache) if path.suffix.lower() == ".sdf" else _read_csv(path, where)
    if not isinstance(options, Mapping):
        return None
    for option, smiles in options.items():
        if not isinstance(option, str) or not option:
            raise ConfigError(f"{where}: every option must be a non-empty name, got {option!r}")
        if not isinstance(smiles, str) or not smiles.strip():
            raise ConfigError(f"{where}: option '{option}' must be given as a SMILES string, got {smiles!r}")
    return {option: smiles.strip() for option, smiles in options.items()}


def smiles_of(raw: Mapping[str, Any]) -> dict[str, dict[str, str]]:
    """The SMILES of the molecular parameters of a loaded config (`PlannerConfig.raw`, or a store's config, where
    options read from a file are written out): parameter -> option -> SMILES."""
    return {spec["name"]: dict(spec["options"]) for spec in raw.get("parameters") or []
            if isinstance(spec, Mapping) and spec.get("type") == "categorical" and isinstance(spec.get("options"),
                                                                                              Mapping)}


def _read_csv(path: Path, where: str) -> dict[str, str]:
    """A CSV with a header naming the columns `name` and `smiles` (any case; other columns are ignored)."""
    try:
        with open(path, newline="") as handle:
            reader = csv.DictReader(handle)
            columns = {c.strip().lower(): c for c in reader.fieldnames or []}
            if not {"name", "smiles"} <= set(columns):
                raise ConfigError(f"{where}: '{path}' needs a header with the columns 'name' and 'smiles', got "
                                  f"{reader.fieldnames}")
            out: dict[str, str] = {}
            for row in reader:
                name = (row.get(columns["name"]) or "").strip()
                if name in out:
                    raise ConfigError(f"{where}: '{path}' line {reader.line_num}: option '{name}' is listed twice")
                out[name] = row.get(columns["smiles"]) or ""
    except OSError as exc:
        raise ConfigError(f"{where}: cannot read '{path}': {exc.strerror}") from None
    return out


def _read_sdf(path: Path, where: str, cache: MoleculeCache | None = None) -> dict[str, str]:
    """An SDF file: each record's name (its first line) -> its canonical SMILES, read with RDKit unless `cache`
    holds a file of the same bytes."""
    try:
        digest = hashlib.sha256(path.read_bytes()).hexdigest()
    except OSError as exc:
        raise ConfigError(f"{where}: cannot read '{path}': {exc.strerror or exc}") from None
    known = cache.sdf(digest) if cache is not None else None
    if known is not None:
        return known
    chem = rdkit(f"{where}: reading '{path}'")
    out: dict[str, str] = {}
    for index, mol in enumerate(chem.SDMolSupplier(str(path))):
        if mol is None:
            raise ConfigError(f"{where}: record {index + 1} of '{path}' is not a valid molecule")
        name = mol.GetProp("_Name").strip() if mol.HasProp("_Name") else ""
        if not name or name in out:
            raise ConfigError(f"{where}: record {index + 1} of '{path}' needs a name of its own (its first line), "
                              f"got {name!r}")
        out[name] = chem.MolToSmiles(mol)
    if cache is not None:
        cache.put_sdf(digest, out)
    return out


def descriptor_columns(spec: Mapping[str, Any]) -> tuple[str, ...]:
    """The computed descriptors a molecular parameter gives the models: `molecular_descriptors`, a set name of
    DESCRIPTOR_SETS (default `default`) or a list of CATALOG names."""
    where = f"parameter '{spec.get('name')}'"
    chosen = spec.get("molecular_descriptors", "default")
    if isinstance(chosen, str):
        if chosen not in DESCRIPTOR_SETS:
            raise ConfigError(f"{where}: 'molecular_descriptors' {chosen!r} is no descriptor set; sets are "
                              f"{sorted(DESCRIPTOR_SETS)}, or give a list of {sorted(CATALOG)}"
                              f"{suggestion(chosen, sorted(DESCRIPTOR_SETS))}")
        return DESCRIPTOR_SETS[chosen]
    if not isinstance(chosen, (list, tuple)) or not all(isinstance(c, str) for c in chosen):
        raise ConfigError(f"{where}: 'molecular_descriptors' must be a set name or a list of descriptor names, got "
                          f"{chosen!r}")
    for name in chosen:
        if name not in CATALOG:
            raise ConfigError(f"{where}: unknown molecular descriptor {name!r}; known: {sorted(CATALOG)}"
                              f"{suggestion(name, sorted(CATALOG))}")
    if len(set(chosen)) != len(chosen):
        raise ConfigError(f"{where}: 'molecular_descriptors' contains duplicates")
    return tuple(chosen)


def substructure_patterns(texts: Iterable[str], molecular: set[str]) -> dict[str, dict[str, str]]:
    """SMARTS asked for by `has_substructure(parameter, "SMARTS")` in constraint expressions: parameter -> SMARTS ->
    the constraint's text (for messages). Calls of another shape are left to the expression compiler to refuse."""
    out: dict[str, dict[str, str]] = {}
    for text in texts:
        try:
            tree = ast.parse(text.strip(), mode="eval")
        except SyntaxError:
            continue
        for node in ast.walk(tree):
            if (isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id == SUBSTRUCTURE
                    and len(node.args) == 2 and isinstance(node.args[0], ast.Name) and node.args[0].id in molecular
                    and isinstance(node.args[1], ast.Constant) and isinstance(node.args[1].value, str)):
                out.setdefault(node.args[0].id, {}).setdefault(node.args[1].value, text)
    return out


def compute(name: str, smiles: Mapping[str, str], columns: tuple[str, ...], patterns: Mapping[str, str],
            cache: MoleculeCache) -> Molecules:
    """Every CATALOG property of each option and its match of each SMARTS pattern (pattern -> constraint text), from
    the cache where it holds them, else by RDKit."""
    where = f"parameter '{name}'"
    features = [*CATALOG, *(f"smarts:{p}" for p in patterns)]
    compiled: dict[str, Any] = {}
    for option, text in smiles.items():
        if all((text, f) in cache for f in features):
            continue
        rdkit(f"{where} (options given as SMILES)")
        mol = parse_smiles(text, f"{where}, option '{option}'")
        if any((text, p) not in cache for p in CATALOG):
            for key, value in properties_of(mol).items():
                cache.put((text, key), value)
        for pattern, constraint in patterns.items():
            if (text, f"smarts:{pattern}") in cache:
                continue
            if pattern not in compiled:
                compiled[pattern] = parse_smarts(pattern, f"constraint {constraint!r}, {SUBSTRUCTURE}({name}, ...)")
            cache.put((text, f"smarts:{pattern}"), float(mol.HasSubstructMatch(compiled[pattern])))
    properties = {p: {o: cache[(s, p)] for o, s in smiles.items()} for p in CATALOG}
    substructures = {p: {o: cache[(s, f"smarts:{p}")] > 0.5 for o, s in smiles.items()} for p in patterns}
    return Molecules(dict(smiles), columns, properties, substructures)


def draw_svg(smiles: str, width: int = 220, height: int = 160) -> str:
    """A 2D drawing of a molecule as SVG text (RDKit's depiction)."""
    mol = parse_smiles(smiles, "drawing a molecule")  # a ConfigError naming the extra without RDKit
    from rdkit.Chem.Draw import rdMolDraw2D
    drawer = rdMolDraw2D.MolDraw2DSVG(width, height)
    drawer.DrawMolecule(mol)
    drawer.FinishDrawing()
    return drawer.GetDrawingText()
