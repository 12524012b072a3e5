"""outfile.drafting: the caller has the last word on whether the new file replaces the old
one (`sim --vcd` cut by Ctrl-C keeps the old dump without raising an exception
of its own to leave the block). Real files in a temporary folder."""
from __future__ import annotations

import os
import signal
import subprocess
import sys

import pytest

from mercmac import outfile
from helpers.files import leftovers
from helpers.paths import ROOT


@pytest.fixture
def old(tmp_path):
    path = tmp_path / "run.vcd"
    path.write_text("the old dump\n", encoding="ascii")
    return path


def test_a_draft_let_go_leaves_the_old_file_and_no_temporary(old):
    with outfile.drafting(old, encoding="ascii") as draft:
        draft.file.write("half a dump\n")
        draft.keep = False
    assert old.read_text(encoding="ascii") == "the old dump\n"
    assert leftovers(old.parent) == []


def test_a_draft_kept_replaces_the_old_file(old):
    with outfile.drafting(old, encoding="ascii") as draft:
        draft.file.write("the new dump\n")
    assert old.read_text(encoding="ascii") == "the new dump\n"
    assert leftovers(old.parent) == []


def test_a_draft_let_go_leaves_every_name_of_a_hard_linked_file(old):
    other = old.parent / "other.vcd"
    os.link(old, other)
    with outfile.drafting(old, encoding="ascii") as draft:
        draft.file.write("half a dump\n")
        draft.keep = False
    assert old.read_text(encoding="ascii") == other.read_text(encoding="ascii") == "the old dump\n"
    assert os.stat(old).st_ino == os.stat(other).st_ino and leftovers(old.parent) == []


def test_a_new_file_let_go_is_never_created(tmp_path):
    path = tmp_path / "new.vcd"
    with outfile.drafting(path) as draft:
        draft.file.write("x")
        draft.keep = False
    assert not path.exists() and leftovers(tmp_path) == []


# A program of its own (not mercmac's command line, which answers SIGTERM itself) whose
# SIGTERM is the default, killing it: the draft it was writing goes before it dies.
KILLED_WHILE_DRAFTING = """
import os, signal, sys
from mercmac import outfile
with outfile.drafting(sys.argv[1], encoding="ascii") as draft:
    draft.file.write("half a dump\\n")
    os.kill(os.getpid(), signal.SIGTERM)
    draft.file.write("never written\\n")
"""


@pytest.mark.skipif(os.name != "posix", reason="POSIX signals")
def test_sigterm_by_default_kills_a_program_drafting_but_not_before_the_draft_goes(old):
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    done = subprocess.run([sys.executable, "-c", KILLED_WHILE_DRAFTING, str(old)], timeout=60,
                          capture_output=True, text=True, env=env)
    assert done.returncode == -signal.SIGTERM, done.stderr  # it still ends as killed
    assert old.read_text(encoding="ascii") == "the old dump\n" and leftovers(old.parent) == []
