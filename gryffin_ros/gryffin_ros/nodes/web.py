"""The planner node's live web page (parameters dashboard_port, dashboard_host): the dashboard reads the campaign's
store, so it needs a store file; a page reachable from other machines is warned about (no authentication)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ..planner import GryffinRosError


class DashboardError(GryffinRosError):
    """The dashboard cannot be served with the parameters given."""


def start_dashboard(storage: str, host: str, port: int, config: str, logger: Any):
    from ..dashboard import start  # the web server and plotly load only when asked for
    if storage == ":memory:":
        raise DashboardError("parameter 'dashboard_port': the dashboard reads the campaign store; give 'storage' a "
                             "file")
    try:
        server = start(storage, host, port, Path(config).resolve().parent)
    except GryffinRosError as exc:
        raise DashboardError(f"parameter 'dashboard_port': {exc}") from None
    logger.info(f"dashboard: {server.url}")
    if not server.loopback:
        logger.warning(f"dashboard on {host}: reachable from other machines, without authentication")
    return server
