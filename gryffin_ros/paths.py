"""Where the files installed beside the package live: msg_schemas/ and examples/ of a source or editable install,
else the copies under <prefix>/share/gryffin_ros."""

from __future__ import annotations

import sys
from pathlib import Path

from .planner.errors import GryffinRosError


def share_path(name: str) -> Path:
    for candidate in (Path(__file__).resolve().parents[1] / name, Path(sys.prefix) / "share" / "gryffin_ros" / name):
        if candidate.is_dir():
            return candidate
    raise GryffinRosError(f"{name}/ not found next to the package or under {sys.prefix}/share/gryffin_ros")
