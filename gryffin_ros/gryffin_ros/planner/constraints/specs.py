"""The entries of a config's `constraints`, typed once when the config is loaded (`load_config`): an expression, a
plugin with its options, or a mixture, each with its position in the list and the user's label. Their shape is checked
here, so a malformed entry is refused at load with its position; an expression's text is parsed once
(`expressions.parse`, shared by every reader of it)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import ConfigError

EXPRESSION_OPTIONS = {"expression", "name"}  # what the built-in `expression` plugin takes


@dataclass(frozen=True)
class ConstraintSpec:
    """One config entry: `expression` (its text), or `plugin` (a name) with `options`, or `mixture` (components,
    total, bounds: read by `LinearEqualities`). `{plugin: expression, options: {expression: ...}}` is the expression
    it names. `name` labels the constraint in messages and violation lists."""

    position: int
    expression: str | None = None
    plugin: str | None = None
    options: Mapping[str, Any] = field(default_factory=dict)
    mixture: Mapping[str, Any] | None = None
    name: str | None = None

    @property
    def where(self) -> str:
        return f"constraints[{self.position}]"

    @classmethod
    def of(cls, entry: Any, position: int, base_dir: Path | None = None) -> ConstraintSpec:
        """The spec of a config entry (an expression string or a mapping); a plugin's relative `file` option is
        taken from `base_dir` (the config's folder). A spec is returned as it is."""
        if isinstance(entry, ConstraintSpec):
            return entry
        where = f"constraints[{position}]"
        if isinstance(entry, str):
            return cls(position, expression=entry)
        if not isinstance(entry, Mapping):
            raise ConfigError(f"{where} must be an expression string or a mapping, got {type(entry).__name__}")
        name = str(entry["name"]) if "name" in entry else None
        if "mixture" in entry:
            if set(entry) - {"mixture", "name"} or not isinstance(entry["mixture"], Mapping):
                raise ConfigError(f"{where}: a mixture is "
                                  "{mixture: {components: [...], total: 1, bounds: {...}}}")
            return cls(position, mixture=entry["mixture"], name=name)
        unknown = set(entry) - {"plugin", "options", "expression", "name"}
        if unknown:
            raise ConfigError(f"{where}: unknown key(s) {sorted(unknown)}")
        if "expression" in entry and "plugin" in entry:
            raise ConfigError(f"{where}: give 'expression' or 'plugin', not both")
        if "expression" in entry and "options" in entry:
            raise ConfigError(f"{where}: 'options' belong to a plugin; an expression takes none")
        if "expression" in entry:
            return cls(position, expression=entry["expression"], name=name)
        plugin = entry.get("plugin")
        if not isinstance(plugin, str):
            raise ConfigError(f"{where}: needs an 'expression' string or a 'plugin' name")
        options = entry.get("options", {})
        if not isinstance(options, Mapping):
            raise ConfigError(f"{where}: constraint plugin '{plugin}': 'options' must be a mapping")
        if plugin == "expression":
            unknown = sorted(set(options) - EXPRESSION_OPTIONS)
            if unknown:
                raise ConfigError(f"{where}: expression constraint: unknown option(s) {unknown}; it takes only "
                                  "'expression'")
            return cls(position, expression=options.get("expression"), name=name)
        if base_dir is not None and isinstance(options.get("file"), str) and not Path(options["file"]).is_absolute():
            options = {**options, "file": str(base_dir / options["file"])}
        return cls(position, plugin=plugin, options=dict(options), name=name)


def constraint_specs(entries: Any, base_dir: Path | None = None) -> list[ConstraintSpec]:
    """The typed specs of a config's `constraints` list."""
    if entries is None:
        return []
    if not isinstance(entries, list):
        raise ConfigError("'constraints' must be a list")
    return [ConstraintSpec.of(entry, i, base_dir) for i, entry in enumerate(entries)]
