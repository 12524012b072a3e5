"""upload.survey.pull_file: the controller half of `mercmac pull` and `decompile --port`,
finding the address as a flash does (upload.chain). The virtual controller on a real pty."""
from __future__ import annotations

import pytest

from contextlib import contextmanager

from mercmac.upload import survey
from mercmac.upload.chain import Watch, flash_chain
from mercmac.upload.flasher import FlashOptions
from helpers.emulator import FAST_TIMING, serve_clocked as serve  # searches: on the line's clock


class Searches:
    """A `searching` that records each time it is entered and each address probed."""

    def __init__(self):
        self.entered, self.probed = 0, []

    @contextmanager
    def __call__(self):
        self.entered += 1
        yield self.probed.append


@pytest.mark.slow
def test_without_an_address_the_only_controller_is_found_and_read():
    searches = Searches()
    with serve(address=7, macros={4: "XN1,MR5"}) as (server, vc):
        pulled = survey.pull_file(server.path, address=None, timing=FAST_TIMING,
                                  searching=searches)
    assert pulled.identity.address == 7 and pulled.macros == {4: "XN1,MR5"}
    assert "[MC04] XN1,MR5" in pulled.text
    assert searches.entered == 1 and searches.probed == list(range(1, 16))


def test_a_given_address_is_read_without_a_search():
    searches = Searches()
    with serve(address=3, macros={2: "TP"}) as (server, vc):
        pulled = survey.pull_file(server.path, address=3, timing=FAST_TIMING, searching=searches)
    assert pulled.identity.address == 3 and pulled.macros == {2: "TP"}
    assert searches.entered == 0


@pytest.mark.slow
def test_flash_and_pull_find_the_same_address(tmp_path):
    program = tmp_path / "p.mcm"
    program.write_text("target C-863\n[MC05] MR5000,WS100\n")
    flashed, pulled = Searches(), Searches()

    class Shown(Watch):
        searching = staticmethod(flashed)

    with serve(address=9) as (server, vc):
        result = flash_chain(server.path, str(program), address=None, timing=FAST_TIMING,
                             options=FlashOptions(backup=tmp_path / "b.mcm"),
                             watch=Shown()).parts[0].result
        back = survey.pull_file(server.path, address=None, timing=FAST_TIMING, searching=pulled)
    assert result.identity.address == back.identity.address == 9
    assert flashed.probed == pulled.probed == list(range(1, 16))
    assert back.macros == {5: "MR5000,WS100"}
