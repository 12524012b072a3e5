"""A `mercmac` process on a real pseudo-terminal, for the interactive modes (`sim
--interactive`, `sim RIG --interactive`): read what its screen received, type keys (POSIX)."""
from __future__ import annotations

import os
import pty
import select
import subprocess
import sys
import time


class Terminal:
    """A child process on the slave side of a pty; we read and type on the master side."""

    def __init__(self, *args: str):
        self.master, slave = pty.openpty()
        env = dict(os.environ, NO_COLOR="1")
        self.proc = subprocess.Popen([sys.executable, "-m", "mercmac", *args], stdin=slave,
                                     stdout=slave, stderr=slave, env=env, close_fds=True)
        os.close(slave)
        self.seen = ""

    def expect(self, text: str, timeout: float = 10.0) -> str:
        """Read until `text` appears in what the screen received since the last expect."""
        deadline = time.monotonic() + timeout
        while text not in self.seen:
            left = deadline - time.monotonic()
            if left <= 0:
                raise AssertionError(f"never saw {text!r}; got {self.seen[-400:]!r}")
            ready, _, _ = select.select([self.master], [], [], left)
            if ready:
                try:
                    self.seen += os.read(self.master, 4096).decode(errors="replace")
                except OSError:  # the child closed the pty
                    break
        assert text in self.seen, f"never saw {text!r}; got {self.seen[-400:]!r}"
        found, self.seen = self.seen, self.seen[self.seen.index(text) + len(text):]
        return found

    def type(self, keys: str) -> None:
        os.write(self.master, keys.encode())

    def close(self) -> int:
        code = self.proc.wait(timeout=10)
        os.close(self.master)
        return code
