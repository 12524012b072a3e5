"""Hypothesis profiles and example budgets: how hard the property tests search.

MERCMAC_HYPOTHESIS_PROFILE picks one (README, Development):
    dev       the default on a developer's machine: the budgets written in the tests, new
              random examples each run, failures replayed from .hypothesis/
    ci        the default where CI is set (CI runners set it, .ci/run's CI does): the same
              budgets, derandomized, so a run is reproducible; no example database
    thorough  ten times the budgets, random: a deliberate long search before a release
No profile has a deadline: the suite runs on busy, shared cores, and speed is measured by
benchmarks/, not asserted by tests.
"""
from __future__ import annotations

import os

from hypothesis import settings

VARIABLE = "MERCMAC_HYPOTHESIS_PROFILE"
SCALE = {"dev": 1, "ci": 1, "thorough": 10}

settings.register_profile("dev", deadline=None)
settings.register_profile("ci", settings.get_profile("ci"), deadline=None)
settings.register_profile("thorough", deadline=None, max_examples=10 * settings().max_examples)


def chosen() -> str:
    """The profile asked for, else `ci` under CI and `dev` elsewhere; a ValueError names the
    choices when the variable holds no profile."""
    name = os.environ.get(VARIABLE) or ("ci" if os.environ.get("CI") else "dev")
    if name not in SCALE:
        raise ValueError(f"{VARIABLE}={name!r}: no such Hypothesis profile "
                         f"(choose {', '.join(SCALE)})")
    return name


def load() -> str:
    name = chosen()
    settings.load_profile(name)
    return name


def budget(examples: int) -> int:
    """A test's own example budget, scaled by the profile (`thorough` searches ten times longer)."""
    return examples * SCALE[chosen()]


def fuzz_budget(examples: int) -> int:
    """A fuzz test's budget: MERCMAC_FUZZ_EXAMPLES when it is set (a one-off long search of one
    file, as the fuzz tests' docstrings show), else `budget(examples)`."""
    forced = os.environ.get("MERCMAC_FUZZ_EXAMPLES")
    return int(forced) if forced else budget(examples)
