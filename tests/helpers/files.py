"""What file writes leave behind."""
from __future__ import annotations

from pathlib import Path


def leftovers(folder: Path) -> list[Path]:
    """The temporary files an interrupted whole-or-nothing write would leave in `folder`."""
    from mercmac import outfile

    return sorted(folder.glob(f"{outfile.TEMP_PREFIX}*{outfile.TEMP_SUFFIX}"))
