"""A lock between processes: what several pytest-xdist workers share runs one at a time."""
from __future__ import annotations

import fcntl
import hashlib
import tempfile
from contextlib import contextmanager
from pathlib import Path


def lock_file(folder: Path) -> Path:
    """The lock file for work in `folder`: in the temporary folder, named by the folder's
    path, so that nothing is written into the tree and two clones never share one."""
    digest = hashlib.sha256(str(folder.resolve()).encode()).hexdigest()[:16]
    return Path(tempfile.gettempdir()) / f"mercmac-tests-{folder.name}-{digest}.lock"


@contextmanager
def held(path: Path):
    """Inside, no other process holds `path` (flock: released when the holder exits or dies).

    pytest-xdist gives no way to run a fixture once for all workers (its docs lock a file
    around it, as here), and `--dist loadgroup` no longer keeps a group on one worker
    under pytest 9: two workers ran `npm ci` in one folder at once."""
    with open(path, "a") as handle:
        fcntl.flock(handle, fcntl.LOCK_EX)  # blocks while another process is inside
        try:
            yield
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)
