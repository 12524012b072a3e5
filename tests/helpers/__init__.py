"""What tests share, one module per noun; fixtures and hooks stay in tests/conftest.py.

    paths        the repository's folders and each example file by name
    compiling    compile a snippet: its rules, its program
    cli          run `mercmac` in-process (click) or as a process; its exit codes; a hang guard
    files        what a whole-or-nothing write leaves behind
    simulation   a simulation run as plain data, stepped or skipped to checkpoints, to compare
    emulator     the virtual controller on a pty, timeouts with room, clocks a test controls;
                 a flash through the library (run_flash)
    locking      a lock between processes (pytest-xdist workers)
    lsp_wire     a real `mercmac lsp` fed raw bytes
    semantics    a model of the firmware and of the structured program, to compare traces
    programs     random well-formed programs and raw commands (Hypothesis strategies)
    readme       the README's code blocks, set-up and other commands, tour program
    rigs         small rig files written to a folder, and the example raster rig
    plots        reading back what `sim --plot` wrote (SVG texts, the HTML page's data)
    terminal     a `mercmac` process on a real pty, for the interactive modes
    formatting   what `fmt` must keep: the build and the comments
    decompiling  the decompiler's round trip: raw macros -> source -> the same macros
    history      the program the flash history tests flash
    budgets      Hypothesis profiles (dev, ci, thorough) and example budgets

Test files import them as `from helpers.cli import cli`, never from another test module
(tests/project/test_suite_layout.py). pyproject's `pythonpath` puts tests/ (never the root of
this tree) on sys.path, and pytest puts conftest.py's folder there too, so `helpers` resolves
from any folder below tests/ and in every pytest-xdist worker. tests/ is no package and the
root is not on the path so that a test of this tree run against an older checkout
(`cd /tmp/base && PYTHONPATH=/tmp/base python -m pytest /work/main/tests/test_x.py`, which
still reads this tree's pyproject) imports that checkout's mercmac, not this one's.
"""
