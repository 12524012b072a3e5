"""The virtual controller behind `mercmac emulate` and the uploader's tests (docs/uploader.md).

    virtual.py     VirtualController: the firmware's serial front end over the VM
    chain.py       Chain: several of them on one link (a daisy chain, a rig's wires live)
    ptyserver.py   serves one or a chain on a pseudo-terminal that opens like a serial port
    faults.py      Faults: how it misbehaves on demand, as real links do
"""
