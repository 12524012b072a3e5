"""The ops a loop adds (RP, WA, EMs of moved blocks) are told from the commands the user
wrote by what they are, not by id(): an id() of an op the lowering dropped is
taken again by a later op, which the too-long-loop message then counted as added."""
from __future__ import annotations

import re

from mercmac.compiler import compile_source
from mercmac.source import Source

# From the lowering coverage generator (seed 101): mode0's `every` line holds 20 ops, of
# which the user wrote 9 (the `call leaf0` of the `repeat 1` included) and the loop adds
# 2 RPs, 1 WA and 8 hoisting EMs. The old lowering, by id(), counted the call as added.
PROGRAM = """\
macro leaf0 { XF 2, MR -22 }
macro sub0 {
  repeat 3 { TT, CF 4, CP 1, CN 2, SV 9000, CN 1, CN 3, SV 5000, TP, CF 4, TT, CP 6, SV 1000, CP 15, TI, TT, CF 3, TP }
  every 24ms { TT, WA 5, call leaf0, call leaf0 }
  when 1 { call leaf0, call leaf0, call leaf0, TT }
  CN 2
}
macro sub1 {
  
}
macro mode0 {
  every 29ms { XF 2, MR 16, CN 4, SV 1000, CN 3, CN 4, CP 3, XF 2, CF 1, WA 7, WA 2, MR -40, CP 12, CN 3, TP, TP, TP, XN 1, WA 4, CP 12, TI, SV 2000, TT, XN 1, CN 1, MR -18, WA 6, TP, TP, TI, MR 42, CF 4, WA 7, CF 2, when 3 { goto mode1 }, repeat 1 { call leaf0, XN 1 }, repeat 2 { CF 3, TP, CN 3, TP, TT, TP, CP 14, TT, CF 1, CP 5, WA 4, TT, TP, TT, MR 5 } }
  CP 15
}
macro mode1 {
  every 18ms { when not 2 and 2 { CF 3, XF 2, MR 43, WA 4, TP, CN 1, WA 5, CP 13, MR 29, CN 4, WA 7, goto mode1 } }
}
autostart {
  call leaf0
  repeat 4 { repeat 2 { CP 12, goto mode1 } }
  TP
}
"""


def test_a_too_long_loop_counts_the_users_call_as_written_not_as_added():
    report = compile_source(Source("gen.mcm", PROGRAM)).report
    loops = [d.message for d in report.items if d.rule.name == "too-many-commands"]
    assert len(loops) == 1
    said = re.search(r"holds (\d+) commands as written, and the compiler adds (.+?) to "
                     r"repeat them: (\d+)", loops[0])
    assert said.groups() == ("9", "2 RPs and 1 WA and 8 EMs", "20")
