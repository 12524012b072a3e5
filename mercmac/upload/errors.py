"""The uploader's errors as people read them: the top layer rewords everything into these.

Each is also of one of the library's kinds (mercmac.errors), which sets its exit code.
"""
from __future__ import annotations

from mercmac.errors import InputError, Interrupted, MercmacError


class UploadError(MercmacError):
    """A flash, pull or scan that could not be done; exit code 1."""


class PortError(UploadError, InputError):
    """The port cannot be opened (missing, busy, no permission); exit code 2 like other I/O."""


class NotChosen(UploadError, InputError):
    """No port or address given, and none stands out: the message lists the candidates
    (exit code 2, as for any option that must be given)."""


class Refused(UploadError):
    """Stopped before the first write: nothing on the controller changed."""


class ProgramUnreadable(Refused, InputError):
    """Stopped before the first write because a program of the rig cannot be read: exit
    code 2, as for any file that cannot be read."""


class FlashFailed(UploadError):
    """Stopped after writing began; the message lists what was written and the backup."""


class FlashInterrupted(FlashFailed, Interrupted):
    """Ctrl-C during a flash; exit code 130 like any interrupted command."""
