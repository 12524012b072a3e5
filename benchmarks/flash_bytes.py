"""Bytes on the wire for flashing the manual's Example 4, against the least any uploader needs.

    python benchmarks/flash_bytes.py [FILE]

Flashes FILE (default examples/macros/manual-example4-four-modes.mcm) to an
empty virtual controller over a pseudo-terminal, then flashes it again
unchanged, counting the bytes both ways at the host's serial port. The
minimum is one read-back of every slot for the backup (`TM` and `TZ` with their
answers), the MD lines themselves, and one read-back of each written macro. At 9600 baud a
byte is 10 bits (8N1), so bytes are time. Exit 1 when a goal is missed: an unchanged re-flash must
write no macro, a full flash must stay within 1.15x the minimum.

The rig case flashes examples/rigs/raster/ to an empty virtual
two-controller chain on one pty in one run, and its minimum is, per controller,
one address selection code (only where the target changes), VE and its answer
(each controller is identified: its model must be the rig's), the backup read,
the MD lines and their read-back; it must stay within 1.10x that.
"""
from __future__ import annotations

import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

from mercmac import mdtext
from mercmac.compiler import compile_file
from mercmac.emulator.chain import Chain
from mercmac.emulator.virtual import Faults, VirtualController
from mercmac.upload.flasher import FlashOptions, flash
from mercmac.upload.protocol import command
from mercmac.emulator.ptyserver import PtyServer
from mercmac.upload.connect import identify, open_controller
from mercmac.upload.transport import Timing

EXAMPLE4 = Path(__file__).resolve().parent.parent / "examples" / "macros" / "manual-example4-four-modes.mcm"
BAUD = 9600
BITS_PER_BYTE = 10  # start bit, 8 data bits, stop bit
GOAL_FULL = 1.15
GOAL_RIG = 1.10
RASTER = Path(__file__).resolve().parent.parent / "examples" / "rigs" / "raster" / "raster.rig.toml"
END = len("\r\n\x03")  # MS176E §6.1.3: CR LF ETX after each report line


@dataclass(frozen=True)
class Count:
    """Bytes of one flash, and how many macros it wrote."""

    sent: int
    received: int
    written: int

    @property
    def total(self) -> int:
        return self.sent + self.received


def listing(macros: dict[int, str], framing: str = "etx-per-line") -> int:
    """Bytes of a TM or TZ answer holding `macros`: 'MCnnn text' lines, or an empty report."""
    if not macros:
        return END
    lines = sum(len(f"MC{s:03d} {t}") + END for s, t in macros.items())
    return lines - (len(macros) - 1) * (framing == "one-etx")  # one ETX for all lines


def minimum(before: dict[int, str], written: dict[int, str], framing: str = "etx-per-line") -> int:
    """The least traffic: back up every slot, send the MD lines, read each written one back."""
    others = {s: t for s, t in before.items() if s}
    backup = len(command(mdtext.tm())) + listing(others, framing) + len(command(mdtext.tz())) + listing(
        {0: before[0]} if 0 in before else {})
    md = sum(len(command(mdtext.md(s, t))) for s, t in written.items())
    verify = sum(len(command(mdtext.tell(s))) + listing({s: t})
                 for s, t in written.items())
    return backup + md + verify


def measure(server: PtyServer, program, backup: Path) -> Count:
    before = server.call(lambda chain: chain.controllers[0].md_count)
    with open_controller(server.path, 0, timing=Timing(timeout=0.5, settle=0.05)) as c:
        who = identify(c)
        flash(c, who, program, FlashOptions(backup=backup))
        sent, received = c.transport.sent, c.transport.received
    return Count(sent, received, server.call(lambda chain: chain.controllers[0].md_count) - before)


def seconds(n: int) -> float:
    return n * BITS_PER_BYTE / BAUD


def main(path: Path = EXAMPLE4, framing: str = "etx-per-line") -> dict[str, float]:
    program = compile_file(str(path)).program
    lines = {s: m.line for s, m in program.macros.items()}
    with tempfile.TemporaryDirectory() as tmp, \
            PtyServer(Chain([VirtualController(faults=Faults(tm_framing=framing))])) as server:
        full = measure(server, program, Path(tmp) / "full.mcm")
        again = measure(server, program, Path(tmp) / "again.mcm")
    need_full, need_again = minimum({}, lines, framing), minimum(lines, {}, framing)
    ratios = {"full": full.total / need_full, "unchanged": again.total / need_again,
              "unchanged_writes": again.written}
    print(f"{path.name}: {len(lines)} macros, TM framing {framing}, {BAUD} baud")
    for name, count, need in (("full flash to an empty controller", full, need_full),
                              ("re-flash, unchanged", again, need_again)):
        print(f"  {name}:")
        print(f"    sent {count.sent} B, received {count.received} B, total {count.total} B "
              f"= {seconds(count.total):.2f} s; macros written: {count.written}")
        print(f"    minimum {need} B = {seconds(need):.2f} s; ratio {count.total / need:.3f}")
    return ratios


def identified(model: str, firmware: str = "2.30") -> int:
    """Bytes of `VE` and its answer (MS176E §6.4 VE), as the virtual controller gives it."""
    from mercmac.vm.reports import VERSION

    return len(command(mdtext.ve())) + len(VERSION.format(model=model, firmware=firmware)) + END


def rig_main(path: Path = RASTER, framing: str = "etx-per-line") -> float:
    """A full flash of the rig PATH to an empty chain: bytes against the minimum; the ratio."""
    from mercmac.rig.open import accept
    from mercmac.upload.protocol import select
    from mercmac.upload.chain import flash_chain

    accepted = accept(str(path))
    rig, programs = accepted.rig, accepted.programs
    need = 0
    for c in rig.controllers:
        lines = {s: m.line for s, m in programs[c.name].program.macros.items()}
        need += len(select(c.address)) + identified(c.model) + minimum({}, lines, framing)
    chain = Chain([VirtualController(c.model, c.address, faults=Faults(tm_framing=framing))
                   for c in rig.controllers])
    with tempfile.TemporaryDirectory() as tmp, PtyServer(chain) as server:
        done = flash_chain(server.path, str(path), timing=Timing(timeout=0.5, settle=0.05),
                           options=FlashOptions(backup=f"{tmp}/"))
    total = done.sent + done.received
    print(f"{path.name}: {len(rig.controllers)} controllers on one port, TM framing {framing}")
    print(f"  full flash of the rig to an empty chain: sent {done.sent} B, received "
          f"{done.received} B, total {total} B = {seconds(total):.2f} s")
    print(f"    minimum {need} B = {seconds(need):.2f} s; ratio {total / need:.3f}")
    return total / need


if __name__ == "__main__":
    file = Path(sys.argv[1]) if len(sys.argv) > 1 else EXAMPLE4
    results = [main(file, framing) for framing in ("etx-per-line", "one-etx")]
    rigs = [rig_main(RASTER, framing) for framing in ("etx-per-line", "one-etx")]
    ok = all(r["full"] <= GOAL_FULL and r["unchanged_writes"] == 0 for r in results)
    ok = ok and all(ratio <= GOAL_RIG for ratio in rigs)
    print(f"goals (full <= {GOAL_FULL}x minimum, unchanged re-flash writes nothing, rig full "
          f"flash <= {GOAL_RIG}x its minimum): {'met' if ok else 'MISSED'}")
    sys.exit(0 if ok else 1)
