"""`mercmac sim`: options in, the simulator library does the work (docs/cli.md).

Heavy modules (the VM, rich, pyvcd) are imported inside the command, so that
`mercmac check`, which imports this module, starts fast.
"""
from __future__ import annotations

import click

from mercmac.cli.common import MODEL_CHOICE, FiniteFloat, run_guarded
from mercmac.cli.upload import file_name
from mercmac.commands import MAX_INT32
from mercmac.errors import EXIT_FAILED, EXIT_OK


@click.command()
@click.argument("file", type=click.Path(dir_okay=False, allow_dash=True))
@click.option("--buttons", default="", metavar="SPEC",
              help='Button script: "1@0-2s,2+3@5s-5.2s" (input B held from T1 to T2, or from T1 on). '
                   "Times without a unit are milliseconds. Overlapping presses of one button merge into one.")
@click.option("--joystick", default="", metavar="SPEC",
              help='A rig\'s joystick: "x=+0.5@1s-3s" holds the branch of controller x (or '
                   "branch X, Y, Z) at deflection -1..1 from T1 to T2, then centred.")
@click.option("--until", "until", default=None, metavar="DURATION",
              help="How long to simulate: 500ms, 10s, 2h, 1500d; a number without a unit is "
                   "milliseconds (--until 3 is 3 ms).  [default: 10s]")
@click.option("--format", "fmt", type=click.Choice(["text", "json"]), default="text",
              show_default=True, help="A timeline for people or JSON for programs.")
@click.option("-v", "--verbose", count=True,
              help="Timeline detail: -v adds macro entries and exits, -vv shows everything.")
@click.option("--trace", is_flag=True, help="Show every executed instruction, disassembled.")
@click.option("--vcd", type=click.Path(dir_okay=False), metavar="OUT", callback=file_name,
              help="Write a Value Change Dump (GTKWave, Surfer) to OUT.")
@click.option("--vcd-limit", type=click.FloatRange(min=0), default=100, show_default=True,
              metavar="MB", help="Stop the VCD before it passes this size (0: no limit).")
@click.option("--plot", type=click.Path(dir_okay=False), metavar="FILE", callback=file_name,
              help="Draw position, buttons, LEDs and macro over time: .png, .svg, .pdf or "
                   ".html (zooms and pans). Needs the extra: pip install 'mercmac[plot]'.")
@click.option("--interactive", is_flag=True,
              help="A live pushbutton box: keys 1-4, r resets (power-on), q quits with a summary.")
@click.option("--hold", default="", metavar="B[+B]",
              help="With --interactive or --web: inputs held at power-on, e.g. 2 or 2+3 (mode "
                   "selection).")
@click.option("--web", is_flag=True,
              help="The box and the stage in the browser: a local page (127.0.0.1, with a "
                   "token in its address) where buttons are held with the mouse, touch or "
                   "keys 1-4; it follows the file as you save it. Ctrl-C stops it.")
@click.option("--port", type=click.IntRange(0, 65535), default=0, metavar="N",
              help="With --web: the port (default: a free one).")
@click.option("--no-open", "no_open", is_flag=True,
              help="With --web: print the address, open no browser.")
@click.option("--stop-when-stdin-closes", "stdin_stops", is_flag=True,
              help="With --web: stop when standard input ends, for an editor that starts it "
                   "on a pipe (the pipe closes when the editor goes).")
@click.option("--speed", type=FiniteFloat(), default=1.0, show_default=True,
              help="Simulated seconds per wall-clock second in --interactive and --web.")
@click.option("--scenario", type=click.Path(dir_okay=False), metavar="FILE.toml",
              callback=file_name,
              help="Timed button steps and expectations; exit 1 on the first that fails. "
                   "Not with --buttons: the scenario's steps are the button script.")
@click.option("--fail-on-hazard", is_flag=True, help="Exit 1 when the run finds any hazard (for CI).")
@click.option("--allow-hazard", "allow", multiple=True, metavar="RULES",
              help="Accept these hazard rules for the run (codes or names, comma-separated or "
                   "repeated), e.g. soft-limit-clamp for jogs that stop at the soft limits: "
                   "shown as accepted, not counted by --fail-on-hazard.")
@click.option("--target", type=MODEL_CHOICE, help="Controller model; overrides the file's `target`.")
@click.option("--cycle", type=FiniteFloat(), default=1.0, show_default=True, metavar="MS",
              help="Time one executed command takes.")
@click.option("--servo-off", is_flag=True,
              help="Start with the servo off (a real controller needs MN; the manual's examples never send it).")
@click.option("--reference-at", type=click.IntRange(-MAX_INT32, MAX_INT32), default=0,
              show_default=True, metavar="POS",
              help="Position of the reference switch that FE searches for.")
@click.option("--hard-limits", default=None, metavar="NEG,POS",
              help="Positions of the limit switches, e.g. -200000,200000 (default: none).")
def sim(file, buttons, joystick, until, fmt, verbose, trace, vcd, vcd_limit, plot, interactive, hold,
        web, port, no_open, stdin_stops, speed, scenario, fail_on_hazard, allow, target, cycle, servo_off,
        reference_at, hard_limits) -> None:
    """Simulate FILE on a virtual controller with a scripted pushbutton box; a rig file
    (*.rig.toml) runs every controller on one clock (--buttons NAME:B@T1-T2).

    Macro 0 starts at power-on (t = 0). A file with errors is not simulated:
    its diagnostics are shown and the exit code is 1.
    """
    def work() -> int:
        from mercmac.cli import run

        request = run.Request(
            file=file, buttons=buttons, until=until, fmt=fmt, trace=trace, vcd=vcd,
            vcd_limit_mb=vcd_limit, plot=plot,
            interactive=interactive, speed=speed, scenario=scenario, target=target,
            cycle_ms=cycle, servo_off=servo_off, reference_at=reference_at,
            hard_limits=hard_limits, fail_on_hazard=fail_on_hazard, hold=hold,
            verbose=verbose, joystick=joystick, allow_hazard=allow, web=web, port=port,
            open_page=not no_open, stdin_stops=stdin_stops)
        return EXIT_OK if run.run(request) else EXIT_FAILED

    run_guarded(work)

