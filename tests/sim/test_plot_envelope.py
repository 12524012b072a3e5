"""The position lane inside a long shifted skip: the band its passes sweep.

Passes too many to draw as copies (plot.COPIED) are drawn as an envelope: in a pixel
column of many passes the position's min and max lie on two straight lines, one pass's
sweep apart, from where the skip starts to where its last pass starts."""
from __future__ import annotations

from helpers.compiling import program_of
from mercmac.sim.plot import PlotObserver, figure
from mercmac.sim.simulate import simulate_program

# out 3000, back 2900: each pass sweeps 3000 counts and ends 100 further on
SAW = "macro m { MR 3000, WS 0, MR -2900, WS 0, goto m }\nautostart { goto m }\n"


def traced(text: str, until_ms: int):
    watch = PlotObserver()
    run = simulate_program(program_of(text), until_ms=until_ms, watch=watch)
    return watch.close(until_ms * 1000), run


def test_a_long_shifted_skip_is_drawn_as_the_band_its_passes_sweep():
    trace, run = traced(SAW, 3_600_000)
    (t, t_to, passes, _), = trace.skips
    (e_t, e_to, (low, high), (last_low, last_high)), = trace.envelopes
    assert (e_t, e_to) == (t, t_to)
    assert high - low == last_high - last_low == 3000  # one pass's sweep
    assert last_low - low == (passes - 1) * 100  # each pass 100 further on
    # the pass after the skip is stepped: it runs inside the band's last column
    after = [x for s, x in trace.position if s >= t_to]
    assert last_low + 100 <= min(after) and max(after) <= last_high + 100
    figure(trace)  # the band is drawn (above the hatching)


def test_a_short_skip_is_drawn_as_copies_without_a_band():
    trace, _ = traced(SAW, 3_000)
    assert trace.skips and not trace.envelopes
