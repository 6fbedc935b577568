"""The import graph keeps the layout of docs/architecture.md: folders do not import each other in a loop, the core
needs no ROS. Read from the source with `ast` (imports inside functions and TYPE_CHECKING blocks count too)."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "gryffin_ros" / "gryffin_ros"


def imported_modules(path: Path) -> set[str]:
    """Absolute names of the modules a file imports (relative imports resolved against its package)."""
    package = path.relative_to(PACKAGE.parent).with_suffix("").parts[:-1]
    if path.name == "__init__.py":
        package = path.relative_to(PACKAGE.parent).parts[:-1]
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            found |= {alias.name for alias in node.names}
        elif isinstance(node, ast.ImportFrom):
            base = list(package[:len(package) - node.level + 1]) if node.level else []
            module = ".".join(base + ([node.module] if node.module else []))
            found.add(module)
            found |= {f"{module}.{alias.name}" for alias in node.names}
    return found


def modules_of(folder: str) -> list[Path]:
    return sorted((PACKAGE / folder).rglob("*.py"))


@pytest.mark.parametrize("folder, forbidden", [
    ("planner/surrogates", "gryffin_ros.planner.acquisition"),  # acquisitions read surrogates, not the reverse
    ("planner", "gryffin_ros.nodes"),  # the core knows nothing of ROS, the CLI, the dashboard or the campaign
    ("planner", "gryffin_ros.cli"),
    ("planner", "gryffin_ros.dashboard"),
    ("planner", "gryffin_ros.campaign"),
    ("planner", "rclpy"),
])
def test_a_folder_does_not_import_what_sits_above_it(folder, forbidden):
    offending = {str(path.relative_to(PACKAGE)): sorted(m for m in imported_modules(path)
                                                        if m == forbidden or m.startswith(forbidden + "."))
                 for path in modules_of(folder)}
    assert not {k: v for k, v in offending.items() if v}


def test_only_the_nodes_import_rclpy():
    users = [str(p.relative_to(PACKAGE)) for p in PACKAGE.rglob("*.py")
             if any(m == "rclpy" or m.startswith("rclpy.") for m in imported_modules(p))]
    assert users and all(u.startswith("nodes/") for u in users), users


def test_the_import_reader_resolves_relative_imports():
    # planner/acquisition/gp.py: "from ..surrogates.gaussian_process import CHUNK, GaussianProcess"
    found = imported_modules(PACKAGE / "planner" / "acquisition" / "gp.py")
    assert "gryffin_ros.planner.surrogates.gaussian_process" in found


def test_the_merit_module_is_pure():
    """Ranking observations needs the objectives alone: no planner, constraints, models or torch."""
    found = imported_modules(PACKAGE / "planner" / "merit.py")
    heavy = ("gryffin_ros.planner.strategies", "gryffin_ros.planner.constraints", "gryffin_ros.planner.surrogates",
             "gryffin_ros.planner.acquisition", "torch", "botorch")
    assert not [m for m in found if m.startswith(heavy)], found
