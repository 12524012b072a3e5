"""Power-on defaults per controller model (MS176E §3.4.1, §3.4.2) and simulator options."""
from __future__ import annotations

from dataclasses import dataclass

from mercmac.commands import C663, C863, COMMANDS, MAX_INT32, MODELS


class ModelError(ValueError):
    """A controller model the simulator does not know."""


@dataclass(frozen=True, slots=True)
class Defaults:
    """What a controller holds after power-on or RT (§6.4 RT: "restored to their defaults")."""

    sv: int
    sa: int
    jh: int
    jl: int
    limits_high: bool  # LH (active high) or LL (active low)
    settings: tuple[tuple[str, int], ...]  # values reported by GP, FP?, WW?, ...


def _settings(model: str) -> tuple[tuple[str, int], ...]:
    """The power-on values of the settings, from the command table (§3.4.1, §3.4.2)."""
    return tuple((c.mnemonic, v) for c in COMMANDS.values() for on, v in c.power_on if on == model)


DEFAULTS = {
    # §3.4.1: SV 45000, SA 400000, LH, LN, BN, JH/JL +-100,000,000; the settings'
    # values (DP 35, DL 2000, WW 5, SM 2000, ...) are in the command table (power_on).
    C863: Defaults(45_000, 400_000, 100_000_000, -100_000_000, True, _settings(C863)),
    # §3.4.2: SV 20000, SA 250000, LL, LN, BN; DC, HC, HT in the command table. The
    # manual gives no soft limits for the C-663, so they start cleared (§6.4 JC values).
    C663: Defaults(20_000, 250_000, MAX_INT32, -MAX_INT32, False, _settings(C663)),
}


@dataclass(frozen=True, slots=True)
class Options:
    """Bench facts the manual leaves open; each has a command-line option in `mercmac sim`."""

    servo_on: bool = True  # docs/simulator.md: the manual's stand-alone examples never send MN
    reference_at: int = 0  # position of the reference switch edge (MS176E §4.3)
    hard_limits: tuple[int, int] | None = None  # (negative, positive) limit switch positions
    address: int = 0  # DIP switches 1-4, what TB reports (§6.4 TB)
    firmware: str = "2.30"  # the version VE reports (§6.4 VE example: "Ver. 2.30")
    accepted: frozenset[str] = frozenset()  # hazard rules the user accepts for the run


def model_name(name: str | None) -> str:
    """'c-663' -> 'C-663'; None -> C-863 (the default: docs/simulator.md); anything else
    is a ModelError."""
    if name is None:
        return C863
    upper = name.upper()
    if upper not in MODELS:
        raise ModelError(f"unknown controller model '{name}': use {' or '.join(MODELS)}")
    return upper
