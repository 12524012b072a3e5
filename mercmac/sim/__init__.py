"""The simulator application on the VM core: `mercmac sim` (SPEC §3, §5).

    simulate.py    one scripted run: power on, press buttons on schedule, run to a time
    record.py      what a run keeps of the machine's events (capped lists, counts)
    run.py         the `sim` command's work: options -> run -> timeline, JSON, trace
    scenario.py    TOML scenarios: timed steps and expectations
    interactive.py the keyboard as a C-170.PB pushbutton box
    vcd.py         Value Change Dump output
    plot.py        the --plot picture (matplotlib, imported only when drawing)

Rendering lives in `mercmac.render.sim`; the VM itself in `mercmac.vm`.
"""
