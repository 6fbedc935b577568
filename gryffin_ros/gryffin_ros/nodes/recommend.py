"""The planner node's asks: the Recommend action, ~/json/recommend and auto-propose, each one ask of the campaign
(`Campaign.recommend` / `auto_proposals`) with the status published when it starts optimizing and when it ends, and
an event for its outcome (`proposals_ready`, `error`).

A Recommend goal's feedback is the ask's stages as overall progress, at most every FEEDBACK_PERIOD_S and at every
change of stage; a cancel request stops the ask at its next checkpoint, and a deactivation or shutdown aborts the
goal with the reason."""

from __future__ import annotations

import time
from collections.abc import Callable

from std_srvs.srv import Trigger

from .. import messages
from ..asks import NotServing
from ..campaign import Campaign
from ..planner import GryffinRosError, Proposal
from ..planner.reporting import Cancelled, ProgressCallback
from . import typed
from .outputs import Outputs
from .typed import Recommend

FEEDBACK_PERIOD_S = 0.1
# overall progress of a recommendation at the start of each stage, and the stage's share
STAGES = {"waiting": (0.0, 0.0), "models": (0.0, 0.1), "optimizing": (0.1, 0.8), "selecting": (0.9, 0.1)}



class Asks:
    def __init__(self, campaign: Campaign, outputs: Outputs, batch_size: Callable[[], int]):
        self._campaign, self._outputs, self._batch_size = campaign, outputs, batch_size

    def _ask(self, make: Callable[[ProgressCallback], list[Proposal]],
             feedback: ProgressCallback | None = None) -> list[Proposal]:
        """`make(progress)`, one of the campaign's asks, reported; raises what the ask raises."""
        started = [False]

        def progress(stage: str, fraction: float, ready: int) -> None:
            if not started[0] and stage != "waiting":
                started[0] = True
                self._outputs.status()  # "optimizing"
            if feedback is not None:
                feedback(stage, fraction, ready)

        try:
            proposals = make(progress)
        except (Cancelled, NotServing):
            self._outputs.status()
            raise
        except GryffinRosError as exc:
            self._outputs.event("error", reason=str(exc))
            self._outputs.status()
            raise
        if proposals:
            self._outputs.event("proposals_ready", reason=f"{len(proposals)} proposal(s) after "
                                                          f"{self._campaign.n_observations} observation(s)")
            self._outputs.status()
        return proposals

    def auto_propose(self) -> None:
        """Publish the next proposals unasked when the campaign says they are due."""
        try:
            proposals = self._ask(lambda progress: self._campaign.auto_proposals(self._batch_size(), progress))
        except GryffinRosError:  # said as an event
            return
        if proposals:
            self._outputs.proposals(proposals)

    def on_json_recommend(self, request: Trigger.Request, response: Trigger.Response) -> Trigger.Response:
        campaign = self._campaign
        try:
            proposals = self._ask(lambda progress: campaign.recommend(self._batch_size(), progress=progress))
        except GryffinRosError as exc:
            response.success = False
            response.message = messages.dump("error", {"error": type(exc).__name__, "reason": str(exc)})
            return response
        response.success = True
        response.message = messages.proposals_message(campaign.name, proposals, campaign.n_observations)
        return response

    def execute_recommend(self, goal_handle) -> Recommend.Result:
        campaign = self._campaign
        count, instrument = goal_handle.request.count or self._batch_size(), goal_handle.request.instrument
        return execute(goal_handle, lambda feedback, cancelled: self._ask(
            lambda progress: campaign.recommend(count, instrument=instrument, progress=progress, cancelled=cancelled),
            feedback), lambda: campaign.n_observations)


def execute(goal_handle, ask: Callable[[ProgressCallback, Callable[[], bool]], list[Proposal]],
            n_observations: Callable[[], int]) -> Recommend.Result:
    """Run a Recommend goal: `ask(feedback, cancelled)` and the goal's end (succeeded, canceled or aborted)."""
    started, last = time.monotonic(), [None, 0.0]

    def feedback(stage: str, fraction: float, ready: int) -> None:
        now = time.monotonic()
        if stage == last[0] and now - last[1] < FEEDBACK_PERIOD_S:
            return
        last[0], last[1] = stage, now
        base, share = STAGES.get(stage, (0.0, 0.0))
        goal_handle.publish_feedback(Recommend.Feedback(stage=stage, progress=base + share * fraction,
                                                        proposals_ready=ready, elapsed_s=now - started))

    result = Recommend.Result()
    try:
        proposals = ask(feedback, lambda: goal_handle.is_cancel_requested)
    except Cancelled as exc:
        result.error, result.n_observations = str(exc), n_observations()
        if goal_handle.is_cancel_requested:
            goal_handle.canceled()
        else:  # the node was deactivated or is shutting down
            goal_handle.abort()
        return result
    except GryffinRosError as exc:
        result.error = str(exc)
        goal_handle.abort()
        return result
    result.proposals = [typed.proposal_message(p) for p in proposals]
    result.n_observations = n_observations()
    goal_handle.succeed()
    return result
