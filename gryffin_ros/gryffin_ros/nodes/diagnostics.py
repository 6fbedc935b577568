"""The planner node's health on /diagnostics: the level from the lifecycle state, the campaign's state, its last
ask and the observations refused recently (read from the campaign's store)."""

from __future__ import annotations

import json
from typing import Any

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue

from ..campaign import Campaign

# rejections within this window make the diagnostics a warning
RECENT_S = 60.0


def planner_status(lifecycle_state: str, campaign: Campaign | None, storage: str, configure_error: str | None,
                   hardware_id: str) -> DiagnosticStatus:
    values: dict[str, Any] = {"lifecycle_state": lifecycle_state}
    last_error = None
    if campaign is None:
        level = DiagnosticStatus.ERROR if configure_error else DiagnosticStatus.WARN
        message = f"configure failed: {configure_error}" if configure_error else lifecycle_state
        name = "gryffin_planner"
    else:
        status = campaign.status()
        recent = campaign.recent_rejections(RECENT_S)
        best, last_ask, last_error = status["best"], campaign.last_ask_s, campaign.last_error
        values.update(campaign=status["campaign"], storage=storage, state=status["state"],
                      observations=status["n_observations"], pending=status["n_pending"], failed=status["n_failed"],
                      rejected_last_minute=len(recent), best="none" if best is None else json.dumps(best["objectives"]),
                      best_experiment_id="" if best is None else best["experiment_id"] or "",
                      last_ask_s="none" if last_ask is None else f"{last_ask:.3f}")
        name = f"gryffin_planner: {status['campaign']}"
        if lifecycle_state != "active":
            level, message = DiagnosticStatus.WARN, lifecycle_state
        elif status["state"] == "error":
            level, message = DiagnosticStatus.ERROR, f"the last recommendation failed: {last_error}"
        elif recent:
            level, message = DiagnosticStatus.WARN, (f"{len(recent)} observation(s) rejected in the last "
                                                     f"{RECENT_S:.0f} s; last: {recent[-1]}")
        elif status["warnings"]:
            level, message = DiagnosticStatus.WARN, "; ".join(status["warnings"])
        else:
            level, message = DiagnosticStatus.OK, status["state"]
    if last_error:
        values["last_error"] = last_error
    return DiagnosticStatus(level=level, name=name, message=message, hardware_id=hardware_id,
                            values=[KeyValue(key=k, value=str(v)) for k, v in values.items()])


def publish(node: Any) -> None:
    """The planner node's status on /diagnostics (every lifecycle state; nothing once it is closing)."""
    if node._closing:
        return
    array = DiagnosticArray()
    array.header.stamp = node.get_clock().now().to_msg()
    array.status = [planner_status(node.lifecycle_state(), node.campaign, node.storage, node.configure_error,
                                   node.get_fully_qualified_name())]
    try:
        node.diagnostics_pub.publish(array)
    except Exception:  # noqa: BLE001 - the context is going away
        if not node._closing:
            raise
