"""The simulator application on the VM core: `mercmac sim` (docs/simulator.md, docs/cli.md).

    simulate.py    one scripted run: power on, press buttons on schedule, run to a time
    record.py      what a run keeps of the machine's events (capped lists, counts)
    scenario.py    TOML scenarios: timed steps and expectations
    vcd.py         Value Change Dump output
    plot.py        the --plot picture (matplotlib, imported only when drawing)
    plot_html.py   the page around the picture for `--plot FILE.html`: zoom and pan
    rig_plot.py    a rig's --plot: a lane per axis, the wires, the path (X against Y)

Rendering lives in `mercmac.render.sim`, which reads these (never the other way); the
`sim` command's work, options to timeline, and the keyboard as a C-170.PB pushbutton box
(`--interactive`) are the command line's: `mercmac.cli.run`, `mercmac.cli.interactive`.
The VM itself is `mercmac.vm`.
"""
