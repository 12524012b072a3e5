"""The flasher's events are one closed set (flasher.EventKind) that render.upload matches
on: a real flash over a pty tells only those, and a log shows each of them."""
from __future__ import annotations

import io

from mercmac.render.upload import FlashProgress
from mercmac.upload.connect import identify
from mercmac.upload.flasher import Event, EventKind, FlashOptions, flash
from helpers.compiling import program_of
from helpers.emulator import connect, serve


def test_a_flash_tells_kinds_of_the_closed_set(tmp_path):
    events: list[Event] = []
    with serve(macros={0: "EM3"}) as (server, vc), connect(server) as c:
        flash(c, identify(c), program_of("[MC00] EM4\n[MC04] GH\n"),
              FlashOptions(reset=True, backup=tmp_path / "b.mcm"), events.append)
    kinds = [e.kind for e in events]
    assert all(isinstance(k, EventKind) for k in kinds)
    assert {EventKind.BACKUP, EventKind.STEP, EventKind.VERIFIED, EventKind.RESET} <= set(kinds)


def test_a_log_shows_every_kind_but_the_step_begun(monkeypatch):
    monkeypatch.delenv("FORCE_COLOR", raising=False)
    out = io.StringIO()  # no terminal: one plain line per event
    with FlashProgress(out) as progress:
        for kind in EventKind:
            progress(Event(kind, f"said by {kind.name}", 1, 2))
    shown = {kind for kind in EventKind if f"said by {kind.name}" in out.getvalue()}
    assert shown == set(EventKind) - {EventKind.STEP}
