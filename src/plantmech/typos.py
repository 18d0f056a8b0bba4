""""Did you mean" for a misspelled name: a command, an option, a choice, a design file's
field or a file name. One rule everywhere (the CLI's usage errors, the design file's unknown
fields, a design file that is not there)."""

from __future__ import annotations


def close_matches(word: str, choices, n: int = 3) -> list[str]:
    """The ``choices`` closest to ``word``, best first: one that differs only in case, else
    those whose difflib ratio is at least 0.6 and within 0.1 of the best."""
    import difflib

    choices = [str(c) for c in choices]
    same_case = [c for c in choices if c.lower() == word.lower() and c != word]
    if same_case:
        return same_case[:n]
    scored = sorted(((difflib.SequenceMatcher(None, word, c).ratio(), c) for c in choices),
                    key=lambda rc: -rc[0])
    best = scored[0][0] if scored else 0.0
    return [c for r, c in scored if r >= 0.6 and r >= best - 0.1][:n]


def did_you_mean(word: str, choices) -> str:
    """' (did you mean 'x'?)' or ' (did you mean 'x' or 'y'?)' for a ``word`` that is not
    one of ``choices``; '' when nothing is close."""
    found = close_matches(word, choices)
    if not found:
        return ""
    return " (did you mean " + " or ".join(f"'{c}'" for c in found) + "?)"
