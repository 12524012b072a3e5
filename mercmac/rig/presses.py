"""What a person can press on a rig (docs/rigs.md): the buttons of the C-170.PB box on the box's
controller, each on the input of its number, only where the box's button is connected
(`box_buttons`) and no wire drives that input; and the joystick's inputs on a controller a
joystick branch goes to. `sim RIG --buttons`, a rig scenario's steps and `sim RIG
--interactive` press nothing else: a press on a wired input would mix with the wire's level
on one line (MR008 says so of a connected button), and a box on another controller, or a
joystick on no branch, is not there to press.
"""
from __future__ import annotations

from mercmac.rig.model import Rig

# MS176E §6.4 XN: "1 to 4: Digital input channel 1 to 4 ... 5: Joystick input 6: Joystick
# button"; the box's button n drives input n (§4.5.1).
JOYSTICK_INPUTS = {5: "joystick input", 6: "joystick button"}


def refusal(rig: Rig, controller: str, number: int) -> str | None:
    """Why input `number` (1-6) of `controller` cannot be pressed on `rig`; None if it can."""
    if number in JOYSTICK_INPUTS:
        return _joystick(rig, controller, number)
    if rig.box is None:
        return ("buttons 1-4 are the C-170.PB box's, and the rig has no box: box = \"NAME\" "
                "in the rig file names the controller it is plugged into")
    if controller != rig.box:
        return f"the box is plugged into {rig.box} (box = \"{rig.box}\"), not into {controller}"
    wires = rig.drivers(controller, number)
    if wires:
        return (f"{controller}.in{number} is driven by the wire {wires[0]}: a press would mix "
                "with the wire's level on that line")
    if number not in rig.box_buttons:
        shown = ", ".join(map(str, rig.box_buttons))
        return (f"button {number} of the box is not connected to {controller} "
                f"(box_buttons = [{shown}])")
    return None


def _joystick(rig: Rig, controller: str, number: int) -> str | None:
    if controller in rig.joystick.values():
        return None
    return (f"input {number} is the {JOYSTICK_INPUTS[number]}, and no joystick branch goes to "
            f"{controller}: the rig's [joystick] table says which branch (X, Y, Z) goes where")
