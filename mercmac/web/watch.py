"""The files of a `sim --web` session, watched so that the page follows the editor's saves
(docs/simulator.md, "Scenarios and the live box"): when the program, or a rig file or one
of its programs, changes on disk, the file is opened and checked again. A clean one powers
on in place of the old; one with errors is listed on the page as `check` words it while
the last good one keeps running.

The files are polled, their modification time and size every PERIOD_S: the standard
library has no change notification that works alike on Linux, macOS and Windows, and a
few files looked at twice a second cost nothing. An editor that saves by writing a new
file and renaming it over the old is seen the same way. A change is read once the files
have stood still for SETTLE_S, so that a save caught half written (truncated, then
written) is not run as a program of its own.
"""
from __future__ import annotations

import os
import threading
from dataclasses import dataclass
from typing import Callable

from mercmac.sim.simulate import Simulation
from mercmac.web.live import Live

PERIOD_S = 0.5
SETTLE_S = 0.1
SETTLE_LOOKS = 20  # a file written for longer than this (2 s) is read as it stands


@dataclass(frozen=True, slots=True)
class Loaded:
    """The file opened again: its simulation, or the problems that keep it from running
    (as `check` words them); and the files it was read from (a rig's programs with it)."""

    sim: Simulation | None
    problems: list[str]
    paths: tuple[str, ...]


Stamp = tuple[int, int] | None  # (modification time in ns, size), None: not there


def _stamp(path: str) -> Stamp:
    try:
        st = os.stat(path)
    except OSError:
        return None
    return st.st_mtime_ns, st.st_size


class Watcher:
    """Looks at the session's files every PERIOD_S on a thread of its own, and reloads the
    live simulation, or shows its problems, when one changed."""

    def __init__(self, live: Live, load: Callable[[], Loaded], paths: tuple[str, ...]):
        self.live, self.load = live, load
        self.stamps = {p: _stamp(p) for p in dict.fromkeys(paths)}
        self.stopping = threading.Event()
        self._thread = threading.Thread(target=self._run, name="mercmac-watch", daemon=True)

    def start(self) -> None:
        self._thread.start()

    def stop(self) -> None:
        self.stopping.set()

    def _run(self) -> None:
        while not self.stopping.wait(PERIOD_S):
            self.look()

    def _stamps(self) -> dict[str, Stamp]:
        return {p: _stamp(p) for p in self.stamps}

    def look(self) -> bool:
        """Look once; whether a file had changed (and the file was opened again)."""
        now = self._stamps()
        if now == self.stamps:
            return False
        for _ in range(SETTLE_LOOKS):
            if self.stopping.wait(SETTLE_S):
                return False
            again, now = now, self._stamps()
            if again == now:
                break
        try:
            loaded = self.load()
        except Exception as e:  # noqa: BLE001 - the session goes on; the page says what broke
            loaded = Loaded(None, [f"mercmac could not open the file again: "
                                   f"{type(e).__name__}: {e} (a bug: please report it)"], ())
        # the stamps taken before opening: a save while it was read is seen next time
        paths = dict.fromkeys((*self.stamps, *loaded.paths))
        self.stamps = {p: now[p] if p in now else _stamp(p) for p in paths}
        if loaded.sim is not None:
            self.live.reload(loaded.sim)
        else:
            self.live.refuse(loaded.problems)
        return True
