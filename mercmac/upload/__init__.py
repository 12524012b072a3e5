"""The uploader: flash, pull and scan Mercury controllers over a serial link (docs/uploader.md).

Layers, each with its own error type that the next one up rewords
(STYLE practice 7):

    protocol.py    bytes: address codes, CR framing, report parsing  -> ProtocolError
    transport.py   pyserial with a timeout on every read             -> TransportError
    controller.py  commands to one controller: VE, TM, TZ, MD, RM     -> ControllerError
    connect.py, plan.py, flasher.py, backup.py, survey.py            -> errors.UploadError
    mercmac/cli/upload.py                                            the click commands

The virtual controller behind `mercmac emulate` and the tests is its own
package, `mercmac.emulator`.
"""
