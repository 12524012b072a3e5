"""'Did you mean ...?': the one measure of how close two words are, and the nearest known word.

Used for mnemonics (mercmac.commands.nearest), macro and const names (compiler/checks.py),
`mercmac explain` keys and the names of mercmac's own commands (cli).
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


def suggest(word: str, known: Iterable[str], limit: int) -> str | None:
    """The known word nearest to `word`, case aside: the same but for case, else the fewest
    edits, at most `limit` (ties: the alphabetically first); None when none is that close."""
    low = word.lower()
    best, best_cost = None, limit
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
