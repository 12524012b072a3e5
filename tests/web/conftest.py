"""The live session of `sim --web` served on 127.0.0.1 for a test (tests/web)."""
from __future__ import annotations

import threading
from pathlib import Path

import pytest

from helpers.web import simulation
from mercmac.web.live import Live
from mercmac.web.server import WebServer


@pytest.fixture
def serve():
    """serve(path, speed) -> a running WebServer for the file; stopped after the test."""
    running = []

    def start(path: Path, speed: float | None = 1.0) -> WebServer:
        server = WebServer(Live(simulation(path), path.name, speed=speed))
        threading.Thread(target=server.serve_forever, daemon=True).start()
        running.append(server)
        return server

    yield start
    for server in running:
        server.shutdown()
        server.server_close()
