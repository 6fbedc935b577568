"""Where the files installed beside the package live: msg_schemas/ and examples/ of a source or editable install,
else the copies under <prefix>/share/gryffin_ros, for the prefix this package is installed in (a colcon install
space: <prefix>/lib/pythonX.Y/site-packages/gryffin_ros) or the environment's (a pip install)."""

from __future__ import annotations

import sys
from pathlib import Path

from .planner.errors import GryffinRosError


def share_path(name: str) -> Path:
    here = Path(__file__).resolve()
    prefixes = [here.parents[4]] if len(here.parents) > 4 and here.parents[3].name == "lib" else []
    prefixes.append(Path(sys.prefix))
    candidates = [here.parents[1] / name] + [prefix / "share" / "gryffin_ros" / name for prefix in prefixes]
    for candidate in candidates:
        if candidate.is_dir():
            return candidate
    raise GryffinRosError(f"{name}/ not found in any of {', '.join(map(str, candidates))}")
