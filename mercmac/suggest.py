"""'Did you mean ...?': the one measure of how close two words are, and the nearest known word.

Used for mnemonics (mercmac.commands.nearest), macro and const names (compiler/checks.py),
`mercmac explain` keys, the names of mercmac's own commands (cli), settings keys
(mercmac.config) and rig file keys and names (mercmac.rig.load); `did_you_mean` is the phrase
their messages end with.
"""
from __future__ import annotations

from typing import Iterable


def distance(a: str, b: str) -> int:
    """Edits from `a` to `b`: insert, delete, replace, or swap two neighbours (optimal string
    alignment, so that `scna` -> `scan` is 1). Words are a few letters long."""
    before: list[int] = []
    row = list(range(len(b) + 1))
    for i in range(1, len(a) + 1):
        current = [i] + [0] * len(b)
        for j in range(1, len(b) + 1):
            current[j] = min(row[j] + 1, current[j - 1] + 1, row[j - 1] + (a[i - 1] != b[j - 1]))
            if i > 1 and j > 1 and a[i - 1] == b[j - 2] and a[i - 2] == b[j - 1]:
                current[j] = min(current[j], before[j - 2] + 1)
        before, row = row, current
    return row[-1]


def suggest(word: str, known: Iterable[str], limit: int | None = None) -> str | None:
    """The known word nearest to `word`, case aside: the same but for case, else the fewest
    edits, at most `limit` (by default a third of its letters, at least one; ties: the
    alphabetically first); None when none is that close."""
    low = word.lower()
    best, best_cost = None, max(1, len(word) // 3) if limit is None else limit
    for name in known:
        if abs(len(name) - len(low)) > best_cost:  # the distance is at least that
            continue
        cost = distance(low, name.lower())
        if cost < best_cost or (cost == best_cost and (best is None or name < best)):
            best, best_cost = name, cost
    return best


def candidates(word: str, known: Iterable[str], limit: int) -> list[str]:
    """Every known word at most `limit` edits from `word`, case aside, nearest first (ties
    alphabetical): a fix that picks one is sure only when there is one (docs/checks.md,
    "Fixes")."""
    low = word.lower()
    near = [(distance(low, name.lower()), name) for name in known
            if abs(len(name) - len(low)) <= limit]
    return [name for cost, name in sorted(near) if cost <= limit]


def did_you_mean(word: str, known: Iterable[str], limit: int | None = None) -> str:
    """"did you mean 'select'?" for the known word nearest to `word` (`suggest`), or "" when
    none is that near: what a message about an unknown word ends with."""
    return question(suggest(word, known, limit))


def question(meant: str | None) -> str:
    """"did you mean 'select'?" for the word `meant` instead of the one written; "" for None."""
    return f"did you mean '{meant}'?" if meant else ""
