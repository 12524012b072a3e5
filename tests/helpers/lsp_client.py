"""Waiting on the pytest-lsp client without missing what the server sends meanwhile.

`client.wait_for_notification` is a coroutine: `asyncio.wait_for` before Python 3.12 runs it
as a task that registers its waiter only at its first step, so a notification that arrives
in between (the server answers a didOpen fast) is missed and the wait runs out. The waiter
here is registered at once, before the caller gives the loop a turn.
"""
from __future__ import annotations

import asyncio

WAIT_S = 30.0  # generous for a busy machine; a server that never answers fails the test


async def next_notification(client, method: str, seconds: float = WAIT_S):
    """The next notification `method` from the server, or TimeoutError after `seconds`."""
    waiter = asyncio.wrap_future(client.protocol.wait_for_notification(method))
    return await asyncio.wait_for(waiter, seconds)
