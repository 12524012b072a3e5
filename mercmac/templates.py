"""The starting programs `mercmac new` writes: commented, and clean under `check` for both
models (tests/cli/test_new.py checks every template with every model).

Each template is a set of files, by path relative to the folder of the file the user
named; `$target` stands for the model, `$rig` for the rig file's name. Comments cite the
manual (MS176E) where a reader will want the whole story.
"""
from __future__ import annotations

import shlex
from string import Template

from mercmac.names import printable

JOG = """\
// A jog program for the C-170.PB pushbutton box (MS176E §3.8.6 shows the manual's own).
// Started by `mercmac new`; try it before a stage is connected:
//   mercmac check $file
//   mercmac sim $file --buttons "1@0-300ms,2@1s-1.5s,3@3s-3.2s" --until 10s
//
//   button 1 / 2: run in the positive / negative direction while held
//   button 3:     go home (position 0, where the stage was at power-on, §3.5)
//   button 4:     one short step per press
// The LED of the active button is lit while it works.
target $target

const FAR = 9999999   // targets the stage never reaches: the move ends with AB (MR -FAR back)
const STEP = 1000     // one press of button 4, in counts (C-863) or microsteps (C-663)

// Velocity and acceleration first, then the motor on (§3.4, §3.5: MN).
macro setup { SV 50000, SA 200000, MN }

autostart {   // macro 0: runs at power-on (§3.8.5)
    call setup
    goto run
}

macro run {
    // Poll the buttons for good: WA20,RP,RP (§3.8.4). Each `when` runs while its button is
    // held; WF waits for the release, AB stops the run, WS waits until on target.
    every 20ms {
        when 1 and not 2 { CP 1, MR FAR, WF 1, AB 1, CP 0 }
        when 2 and not 1 { CP 2, MR -FAR, WF 2, AB 1, CP 0 }
        when 3 { CP 4, GH, WS 0, CP 0 }
        when 4 { CP 8, MR STEP, WS 10, WF 4, CP 0 }
    }
}
"""

SCAN = """\
// A stepped scan with a camera trigger: press button 1 on the C-170.PB box and the stage
// makes STEPS steps of STEP, settles after each and fires a pulse on output 4 (pin 8 of
// the I/O socket, §4.5.1), then returns to its start and waits for the next press.
// Started by `mercmac new`; try it before a stage is connected:
//   mercmac check $file
//   mercmac sim $file --buttons "1@0-100ms" --until 10s
// LED 1 is lit while the scan runs. For pulses at positions while the stage moves on
// its own, see the trigger modes (ZM, ZP, ZI: §4.5.2; `mercmac explain ZM`).
target $target

const STEP = 500      // one step, in counts (C-863) or microsteps (C-663)
const STEPS = 20      // steps per scan
const BACK = -10000   // STEP * STEPS, back to the start
const SETTLE = 50     // ms to wait on target before the pulse (WS)

macro pulse { CN 4, WA 5, CF 4 }   // a 5 ms pulse on output 4

macro idle {
    every 50ms {   // poll the button for good: WA50,RP,RP (§3.8.4)
        when 1 { goto scan }
    }
}

macro scan {
    CP 1
    repeat STEPS { MR STEP, WS SETTLE, call pulse }   // RP: repeat (§6.4)
    MR BACK, WS 0
    CP 0
    goto idle
}

autostart {                   // macro 0: runs at power-on (§3.8.5)
    SV 20000, SA 200000, MN   // velocity, acceleration, motor on (§3.4, §3.5)
    goto idle
}
"""

RIG = """\
# A two-axis raster scan: two controllers on one RS-232 daisy chain (MS176E §3.2), which
# work together in stand-alone mode through wired I/O lines (§4.5.1).
#   X sweeps one line, then raises out1 ("line done").
#   Y waits for in1, steps one row, then raises out2 ("row stepped").
#   X waits for in2 before it sweeps the next line (back the other way).
# The C-170.PB box is plugged into X's I/O socket: button 1 starts the scan, button 3
# stops it after the current pair of lines.
# Started by `mercmac new`; try it before the controllers are connected:
#   mercmac check $rig
#   mercmac sim $rig --buttons x:1@0-100ms --until 30s
# The rig's name is this file's name before .rig.toml (a `name` key may set another).
box = "x"
box_buttons = [1, 3]
wires = [
  "x.out1 -> y.in1",   # X finished a line: Y steps one row
  "y.out2 -> x.in2",   # Y finished its step: X sweeps the next line
]

[controllers.x]
address = 0            # the DIP switches (§3.1.3): 1-4 all ON
model = "$target"
program = "x.mcm"

[controllers.y]
address = 1            # DIP switch 4 OFF
model = "$target"
program = "y.mcm"
"""

RIG_X = """\
// The raster's X axis (address 0 in $rig): sweeps the lines. Button 1 of the box
// starts the scan, button 3 stops it after the current pair of lines.
// Output 1 -> Y's input 1: "line done". Y's output 2 -> input 2: "row stepped" (§4.5.1).
target $target

const LINE = 20000    // one line, in counts (C-863) or microsteps (C-663)
const BACK = -20000   // the way back

// The four-phase handshake with Y: say the line is done, wait until Y has stepped a
// row, take the signal back, and wait until Y has taken its own back.
macro next_row { CN 1, WN 2, CF 1, WF 2 }

macro idle {
    every 50ms {
        when 1 { goto scan }
    }
}

macro scan {   // one pair of lines, forward and back; WS 10: settle 10 ms
    MR LINE, WS 10
    call next_row
    MR BACK, WS 10
    call next_row
    when 3 { goto idle }
    goto scan
}

autostart {   // macro 0: runs at power-on (§3.8.5); no SC in a chain (§3.1.2)
    SV 20000, SA 200000, MN
    CP 0
    goto idle
}
"""

RIG_Y = """\
// The raster's Y axis (address 1 in $rig): steps one row per line.
// Input 1 <- X's output 1: "line done". Output 2 -> X's input 2: "row stepped" (§4.5.1).
target $target

const ROW = 500   // the row pitch, in counts (C-863) or microsteps (C-663)

// Wait until X has finished a line, step one row, say so, and take the signal back
// once X has taken its own back.
macro row {
    WN 1
    MR ROW, WS 10
    CN 2
    WF 1
    CF 2
    goto row
}

autostart {   // macro 0: runs at power-on (§3.8.5)
    SV 10000, SA 200000, MN
    CP 0
    goto row
}
"""

# name -> (what it is, the files: path relative to the named file's folder -> text);
# "" stands for the named file itself.
TEMPLATES: dict[str, tuple[str, dict[str, str]]] = {
    "jog": ("buttons 1-4 jog a stage, go home and step", {"": JOG}),
    "scan": ("button 1 starts a stepped scan with a trigger pulse at each step", {"": SCAN}),
    "raster-rig": ("a rig: X sweeps, Y steps a row per line, wired I/O handshakes",
                   {"": RIG, "x.mcm": RIG_X, "y.mcm": RIG_Y}),
}
RIG_TEMPLATES = {"raster-rig"}  # the templates whose named file is a rig file


def files(template: str, name: str, target: str) -> dict[str, str]:
    """The files TEMPLATE makes for the file NAME (a file name, no folder) and the model
    TARGET: file name -> text, the named file first."""
    shown = shlex.quote(printable(name))  # in a comment: one line, and a command to copy
    rig = shown if template in RIG_TEMPLATES else ""
    return {path or name: Template(text).substitute(target=target, file=shown, rig=rig)
            for path, text in TEMPLATES[template][1].items()}
