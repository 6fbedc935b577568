"""The wire contract: JSON Schemas of msg_schemas/ loaded once, validation of every payload in and out, and the
conversions between JSON payloads and domain objects. No ROS here, so the CLI and tests use it too.
"""

from __future__ import annotations

import json
import time
from functools import cache
from typing import Any

import jsonschema

from .paths import share_path
from .planner.domain import Proposal
from .planner.errors import GryffinRosError

SCHEMAS = ("observation", "proposals", "event", "status", "error")
# Larger messages are refused before they are parsed.
MAX_MESSAGE_BYTES = 1 << 20


class MessageError(GryffinRosError):
    """A payload is not valid JSON or does not follow its schema. `experiment_id`: the id the refused message gives
    (one observation, or a list of one), so that the refusal names it; None when it gives none."""

    def __init__(self, reason: str, experiment_id: str | None = None) -> None:
        super().__init__(reason)
        self.experiment_id = experiment_id


def experiment_id_in(document: Any) -> str | None:
    """The experiment id a parsed but invalid document names, if it names exactly one."""
    if isinstance(document, list) and len(document) == 1:
        document = document[0]
    if isinstance(document, dict) and isinstance(document.get("experiment_id"), str):
        return document["experiment_id"] or None
    return None


@cache
def validator(name: str) -> jsonschema.protocols.Validator:
    schema = json.loads((share_path("msg_schemas") / f"{name}.schema.json").read_text())
    cls = jsonschema.validators.validator_for(schema)
    cls.check_schema(schema)
    return cls(schema)


def _reject_constant(value: str) -> None:
    raise ValueError(f"{value} is not valid JSON")


def parse(name: str, text: str, max_bytes: int = MAX_MESSAGE_BYTES) -> Any:
    """Parse and validate an incoming payload; raises MessageError with a reason a sender can act on."""
    if len(text) > max_bytes or len(text.encode("utf-8", errors="replace")) > max_bytes:
        raise MessageError(f"message larger than {max_bytes} bytes")
    try:
        document = json.loads(text, parse_constant=_reject_constant)
    except RecursionError:
        raise MessageError("JSON nested too deeply") from None
    except ValueError as exc:
        raise MessageError(f"malformed JSON: {exc}") from None
    try:
        check(name, document)
    except RecursionError:
        raise MessageError("JSON nested too deeply") from None
    except MessageError as exc:
        raise MessageError(str(exc), experiment_id_in(document)) from None
    return document


def check(name: str, document: Any) -> None:
    error = jsonschema.exceptions.best_match(validator(name).iter_errors(document))
    if error is not None:
        where = "/".join(str(p) for p in error.absolute_path) or "(root)"
        raise MessageError(f"{name} message invalid at {where}: {error.message}")


def dump(name: str, document: Any) -> str:
    """Validate an outgoing payload and serialize it (a failure here is a bug of ours, not the sender's)."""
    check(name, document)
    return json.dumps(document, allow_nan=False)


def proposals_message(campaign: str, proposals: list[Proposal], n_observations: int) -> str:
    return dump("proposals", {"campaign": campaign, "proposals": [p.to_dict() for p in proposals],
                              "n_observations": n_observations, "created": time.time()})


def observation_items(document: Any) -> list[dict]:
    """An observation payload is one observation or a list of them."""
    return document if isinstance(document, list) else [document]
