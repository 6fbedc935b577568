"""The planner node's parameters: their defaults and descriptions, which are read-only, and what each accepts."""

from __future__ import annotations

from typing import Any

from .. import messages

PARAMETERS = {
    "config": ("", "path to the campaign config (YAML or JSON; Gryffin format accepted); required; read-only"),
    "storage": ("", "SQLite file holding the campaign (default <campaign name>.sqlite); ':memory:' for none; "
                    "read-only"),
    "seed": (-1, "random seed; -1 = random (kept in the store, so a restart continues with it); read-only"),
    "autostart": (True, "configure and activate at start-up (false: wait for a lifecycle manager); read-only"),
    "batch_size": (1, "proposals per recommendation (a Recommend goal with count 0, ~/json/recommend, auto-propose)"),
    "acquisition_optimizer": ("", "'adam' (Adam + Hill) or 'genetic'; empty: as the config's general section says"),
    "auto_propose": (True, "publish the next proposals as soon as all pending experiments have reported"),
    "accept_unsolicited": (False, "accept observations whose experiment_id this planner never proposed"),
    "max_message_bytes": (messages.MAX_MESSAGE_BYTES, "larger incoming JSON messages are refused unparsed"),
    "dashboard_port": (-1, "serve the campaign's live web page on this port (0: any free port; -1: none)"),
    "dashboard_host": ("127.0.0.1", "address the web page binds to (default: this machine only)"),
    "record": ("", "record every typed message the planner publishes or receives into this new bag folder (rosbag2 "
                   "layout, MCAP); empty: off; read-only"),
}
READ_ONLY = ("config", "storage", "seed", "autostart", "record")


def check_parameter(name: str, value: Any) -> str | None:
    """Why `value` is not acceptable for parameter `name` (None when it is)."""
    if name == "config" and not value:
        return "parameter 'config' is required (path to a YAML or JSON campaign config)"
    if name == "batch_size" and value < 1:
        return f"parameter 'batch_size' must be at least 1, got {value}"
    if name == "acquisition_optimizer" and value not in ("", "adam", "genetic"):
        return f"parameter 'acquisition_optimizer' must be 'adam', 'genetic' or empty, got {value!r}"
    if name == "max_message_bytes" and value < 1024:
        return f"parameter 'max_message_bytes' must be at least 1024, got {value}"
    if name == "dashboard_port" and not -1 <= value <= 65535:
        return f"parameter 'dashboard_port' must be -1 (none), 0 (any free port) or a port up to 65535, got {value}"
    if name == "dashboard_host" and not value:
        return "parameter 'dashboard_host' must name an address (127.0.0.1: this machine only)"
    return None


def settings(acquisition_optimizer: str) -> dict[str, Any] | None:
    """The campaign settings a node parameter chooses (how to optimize, not what: the campaign stays the same)."""
    return {"acquisition_optimizer": acquisition_optimizer} if acquisition_optimizer else None
