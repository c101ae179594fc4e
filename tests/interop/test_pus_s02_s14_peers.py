"""Services 2 and 14: neither spacepackets nor puslib defines their application data, so the
packets are checked at the level both define: every new TC our users build decodes in both
peers with its application data intact, and a spacepackets TC[14,11] is served by us, its
TM[14,12] read by spacepackets."""

import struct
import sys
from pathlib import Path

from puslib.packet import PusTcPacket as PuslibTc
from spacepackets.ecss.tc import PusTc as SpTc
from spacepackets.ecss.tm import PusTm as SpTm

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "core"))

from obsw.pus.services.s02_device_access import DeviceUser  # noqa: E402
from obsw.pus.services.s14_forwarding import ForwardingControl, ForwardingUser  # noqa: E402
from pus_loop import APID, Loop  # noqa: E402


def test_our_new_tcs_decode_in_both_peers():
    loop = Loop()
    dev = loop.ground.register(DeviceUser())
    fwd = loop.ground.register(ForwardingUser())
    sent = [
        (dev.on_off(APID, [0x0A81, 0x0A00]), b"\x02\x0a\x81\x0a\x00"),
        (dev.load_registers(APID, {0x000A0001: 5}), b"\x01\x00\x0a\x00\x01\x00\x00\x00\x05"),
        (dev.cpdu(APID, [(0x0A02, 500)]), b"\x01\x0a\x02\x01\xf4"),
        (dev.dump_registers(APID, [0x000A0001]), b"\x01\x00\x0a\x00\x01"),
        (fwd.add_diag(APID, {APID: [5]}), b"\x01\x00\x0a\x01\x00\x05"),
        (fwd.delete_diag(APID, {}), b"\x00"),
        (fwd.report_diag(APID), b""),
    ]
    for (tx, app_data), raw in zip(sent, loop.up):
        sp = SpTc.unpack(raw)
        pl = PuslibTc.deserialize(raw)
        assert (sp.service, sp.message_subtype) == (pl.service, pl.subservice)
        assert (sp.service, sp.message_subtype) == (tx.tc.service, tx.tc.subtype)
        assert sp.app_data == (pl.app_data or b"") == app_data


def test_a_spacepackets_tc_is_served_and_its_report_read_by_spacepackets():
    loop = Loop()
    loop.app.register(ForwardingControl())
    loop.app.receive(SpTc(apid=APID, service=14, message_subtype=11, seq_count=1).pack())
    loop.pump()
    (raw,) = [r for r, t in zip(loop.raw, loop.tm) if (t.service, t.subtype) == (14, 12)]
    tm = SpTm.unpack(raw, timestamp_len=6)
    # N APIDs; the own APID with N2 = 0 SIDs: every diagnostic SID forwarded
    assert tm.source_data == bytes([1]) + struct.pack(">H", APID) + bytes([0])
