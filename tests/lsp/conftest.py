"""The language client the LSP tests drive `mercmac lsp --stdio` with (pytest-lsp, the test
extra): started and initialized, shut down after each test. A test module that must
initialize the session itself (its own capabilities or settings) defines its own `client`."""
from __future__ import annotations

import sys

try:
    import pytest_lsp
    from lsprotocol import types as t
    from pytest_lsp import ClientServerConfig, LanguageClient
except ImportError:  # without the extra the modules that need it skip themselves
    pytest_lsp = None

if pytest_lsp is not None:
    @pytest_lsp.fixture(config=ClientServerConfig(
        server_command=[sys.executable, "-m", "mercmac", "lsp", "--stdio"]))
    async def client(lsp_client: LanguageClient):
        await lsp_client.initialize_session(
            t.InitializeParams(capabilities=t.ClientCapabilities()))
        yield
        await lsp_client.shutdown_session()
