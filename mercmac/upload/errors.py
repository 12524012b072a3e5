"""The uploader's errors as people read them: the top layer rewords everything into these."""
from __future__ import annotations

from mercmac.errors import EXIT_INTERRUPTED, EXIT_USAGE, MercmacError


class UploadError(MercmacError):
    """A flash, pull or scan that could not be done; exit code 1."""


class PortError(UploadError):
    """The port cannot be opened (missing, busy, no permission); exit code 2 like other I/O."""

    exit_code = EXIT_USAGE


class Refused(UploadError):
    """Stopped before the first write: nothing on the controller changed."""


class FlashFailed(UploadError):
    """Stopped after writing began; the message lists what was written and the backup."""


class FlashInterrupted(FlashFailed):
    """Ctrl-C during a flash; exit code 130 like any interrupted command."""

    exit_code = EXIT_INTERRUPTED
