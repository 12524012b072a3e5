"""The simulator core: a bytecode VM of a Mercury controller (docs/simulator.md).

    Machine(program, model=..., cycle_ms=1.0, options=Options(...), on_report=f,
            listeners=[g, ...])  # g(event) hears every vm.events record, in order
    .power_on() .load(p) .define(slot, ops) .execute_line(ops) .start_macro(n) .stop()
    .run_until(t_ms) .set_input(n, on) .running .now_ms .macro .position() .target
    .velocity() .outputs_pattern() .status() .snapshot() .error
    for applications (emulator, scenarios, the box): .stored_macros() .setting(name)
    .set_error(code) .take_restart() .take_self_select() .moving() .label .input(n) .input_lines()
    .now_us .cycle_ms; Options(firmware=...) is the version VE reports

Report strings live in `mercmac.vm.reports`.
"""
from mercmac.vm.machine import Hardware, Machine
from mercmac.vm.models import Options

__all__ = ["Hardware", "Machine", "Options"]
