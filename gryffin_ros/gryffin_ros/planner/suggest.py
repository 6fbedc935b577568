"""Did you mean …? The closest of a set of names or values to a misspelt one, for error messages."""

from __future__ import annotations

import difflib
from collections.abc import Sequence
from typing import Any


def closest(value: Any, choices: Sequence[Any]) -> Any | None:
    """The choice a misspelt `value` most likely meant (case and surrounding blanks first, then similar text;
    for numbers the nearest), or None when nothing is close."""
    if not choices:
        return None
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        numbers = [c for c in choices if isinstance(c, (int, float)) and not isinstance(c, bool)]
        return min(numbers, key=lambda c: abs(c - value)) if numbers else None
    text = str(value)
    folded = text.strip().casefold()
    for choice in choices:
        if str(choice).strip().casefold() == folded:
            return choice
    by_text = {str(c): c for c in choices}
    match = difflib.get_close_matches(text, list(by_text), n=1, cutoff=0.6)
    if not match:
        match = difflib.get_close_matches(folded, [t.casefold() for t in by_text], n=1, cutoff=0.6)
        if match:
            return next(c for t, c in by_text.items() if t.casefold() == match[0])
        return None
    return by_text[match[0]]


def suggestion(value: Any, choices: Sequence[Any]) -> str:
    """"; did you mean 'X'?" when a choice is close, else ""."""
    guess = closest(value, choices)
    return "" if guess is None else f"; did you mean {guess!r}?"
