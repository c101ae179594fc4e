"""COP-1 interop with ccsds-cop (test-only, GPL): our FARM under its FOP, our FOP over its FARM,
and both FARMs and FOPs side by side on the same inputs.

ccsds-cop speaks USLP frames; the TC frame fields COP-1 uses (bypass and control command flags,
sequence number, data) map one to one, and the CLCW goes across as its 4 packed bytes.
"""

import random

import ccsds_cop  # noqa: F401
from ccsds_cop.cop_1 import ControlWord, Gvcid  # noqa: E402
from ccsds_cop.cop_1 import farm as their_farm  # noqa: E402
from ccsds_cop.cop_1 import fop as their_fop  # noqa: E402
from obsw.frames import cltu  # noqa: E402
from obsw.frames import farm as our_farm  # noqa: E402
from obsw.frames import fop as F  # noqa: E402
from obsw.frames.clcw import Clcw  # noqa: E402
from obsw.frames.tc import UNLOCK, TcFrame, set_vr_command  # noqa: E402
from spacepackets.uslp import (  # noqa: E402
    BypassSequenceControlFlag,
    PrimaryHeader,
    ProtocolCommandFlag,
    SourceOrDestField,
    TfdzConstructionRules,
    TransferFrame,
    TransferFrameDataField,
    UslpProtocolIdentifier,
)

SCID = 42
GVCID = Gvcid(0b1100, SCID, 0)
R = their_fop.ResponseType
D = their_fop.DirectiveType


# -- adapters between the two frame models ------------------------------------------------


def to_uslp(frame):
    header = PrimaryHeader(
        SCID,
        SourceOrDestField.SOURCE,
        frame.vcid,
        0,
        0,
        BypassSequenceControlFlag(int(frame.bypass)),
        ProtocolCommandFlag(int(frame.control)),
        vcf_count_len=1,
        vcf_count=frame.seq,
    )
    tfdf = TransferFrameDataField(
        TfdzConstructionRules.VpNoSegmentation,
        UslpProtocolIdentifier.SPACE_PACKETS_ENCAPSULATION_PACKETS,
        frame.data,
    )
    return TransferFrame(header, tfdf)


def from_request(req):
    return TcFrame(SCID, 0, req.tfdf, req.v_s, req.bypass_flag == 1, req.command_flag == 1)


def over_the_air(frame):
    """TC frame -> CLTU -> decoded TC frame, as the spacecraft would see it."""
    data, _ = cltu.decode(cltu.encode(frame.pack()))
    return TcFrame.unpack(data, trailing=True)


def their_clcw(farm):
    return ControlWord(
        vcid=0,
        lockout=farm.lockout,
        wait=farm.wait,
        retransmit=farm.retransmit,
        farm_b_counter=farm.b_counter & 3,
        report_value=farm.v_r,
    ).pack()


class TheirFop:
    """ccsds-cop's FOP-1 with lower procedures that accept every frame at once."""

    def __init__(self, limit=5, k=10):
        self.fop = their_fop.Fop1(GVCID, k=k, timer_initial_value=10000)
        self.rid = 0
        self.bc_pending = False
        for r in (R.AD_ACCEPTED, R.BC_ACCEPTED):  # its BD_ACCEPTED needs a pending FDU
            self.fop.on_receive_response_from_lower_layer(their_fop.Response(GVCID, r))
        self.directive(D.SET_TRANSMISSION_LIMIT, limit)

    def directive(self, kind, qualifier=0):
        self.rid += 1
        self.fop.on_receive_directive(their_fop.DirectiveRequest(GVCID, self.rid, kind, qualifier))
        return self.frames()

    def send(self, fdu):
        self.rid += 1
        req = their_fop.RequestToTransferFdu(GVCID, self.rid, fdu, their_fop.ServiceType.AD)
        self.fop.on_receive_request_to_transfer_fdu(req)
        return self.frames()

    def clcw(self, raw):
        self.fop.on_clcw_arrived(ControlWord.unpack(raw))
        return self.frames()

    def frames(self):
        out = []
        q = self.fop.interface.to_lower
        while q:
            item = q.pop()  # oldest first: the queue is filled from the left
            if isinstance(item, their_fop.TransmitRequestForFrame):
                out.append(from_request(item))
                if item.command_flag == 1:
                    self.bc_pending = True
                else:
                    self.fop.on_receive_response_from_lower_layer(
                        their_fop.Response(GVCID, R.AD_ACCEPTED)
                    )
        # Its BC accept in "Initializing with BC" looks for a BC frame it never queued; answer
        # once the state has moved on.
        if self.bc_pending and self.fop.state != their_fop.FopState.INITIALIZING_WITH_BC:
            self.bc_pending = False
            self.fop.on_receive_response_from_lower_layer(their_fop.Response(GVCID, R.BC_ACCEPTED))
        return out

    def close(self):
        self.fop.cancel_timer()


class TheirFarm:
    def __init__(self):
        self.farm = their_farm.Farm1(10)
        self.delivered = []

    def frame(self, frame):
        self.farm.lower_interface.buffer.append(to_uslp(frame))
        self.farm.lower_interface.signal.append(their_farm.ValidFrameArrivedIndication(GVCID))
        self.farm.tick()
        buf = self.farm.higher_interface.buffer
        while buf:
            f = buf.pop()
            if f.header.prot_ctrl_cmd_flag == ProtocolCommandFlag.USER_DATA:
                self.delivered.append(bytes(f.tfdf.tfdz))

    def clcw(self):
        return their_clcw(self.farm)


def drain(farm):
    out = []
    while True:
        f = farm.take()
        if f is None:
            return out
        if f.type_name != "BC":
            out.append(f.data)


# -- their FOP, our FARM ------------------------------------------------------------------


def test_their_fop_our_farm_with_loss():
    fop = TheirFop()
    farm = our_farm.Farm1(0, 10)
    delivered = []
    try:
        fop.directive(D.INITIATE_AD_NO_CLCW)
        assert fop.fop.state == their_fop.FopState.ACTIVE
        lose = {3, 7}
        fdus = [b"fdu %d" % i for i in range(12)]
        for fdu in fdus:
            frames = fop.send(fdu)
            while frames:
                nxt = []
                for f in frames:
                    if f.seq in lose:
                        lose.discard(f.seq)
                        continue
                    farm.on_frame(over_the_air(f))
                    delivered.extend(drain(farm))
                    nxt.extend(fop.clcw(farm.clcw().pack()))
                frames = nxt
        assert delivered == fdus
        assert fop.fop.nn_r == farm.vr == 12
        assert fop.fop.state == their_fop.FopState.ACTIVE
    finally:
        fop.close()


def test_their_unlock_and_set_vr_on_our_farm():
    fop = TheirFop()
    farm = our_farm.Farm1(0, 10)
    try:
        farm.on_frame(TcFrame(SCID, 0, b"x", 100))  # far outside the window: lockout
        assert farm.state == our_farm.LOCKOUT
        for f in fop.directive(D.INITIATE_AD_WITH_UNLOCK):
            assert (f.type_name, f.data) == ("BC", UNLOCK)
            farm.on_frame(over_the_air(f))
        assert farm.state == our_farm.OPEN
        fop.clcw(farm.clcw().pack())
        assert fop.fop.state == their_fop.FopState.ACTIVE
        fop.directive(D.TERMINATE_AD)
        for f in fop.directive(D.INITIATE_AD_WITH_SET_V_R, 77):
            assert f.data == set_vr_command(77)
            farm.on_frame(over_the_air(f))
        assert farm.vr == 77
        fop.clcw(farm.clcw().pack())
        assert fop.fop.state == their_fop.FopState.ACTIVE
        frames = fop.send(b"after set")
        assert [f.seq for f in frames] == [77]
        farm.on_frame(over_the_air(frames[0]))
        assert drain(farm) == [b"after set"]
    finally:
        fop.close()


# -- our FOP, their FARM ------------------------------------------------------------------


def test_our_fop_their_farm_with_loss_and_duplicates():
    fop = F.Fop1(SCID, 0, window=5, t1=1.0)
    farm = TheirFarm()
    fop.directive(F.INITIATE_AD_NO_CLCW, now=0)
    rng = random.Random(7)
    fdus = [b"cmd %02d" % i for i in range(30)]
    todo = list(fdus)
    now = 0.0
    for _ in range(5000):
        now += 0.1
        if todo and fop.ready:
            fop.send_ad(todo.pop(0), now)
        for f in fop.take_frames():
            if rng.random() < 0.15:
                continue
            for _ in range(1 + (rng.random() < 0.2)):
                farm.frame(over_the_air(f))
            fop.on_clcw(Clcw.unpack(farm.clcw()), now)
        fop.tick(now)
        assert not [n for n in fop.take_notifications() if n[0] == F.ALERT]
        if not todo and fop.outstanding == 0:
            break
    assert farm.delivered == fdus
    assert fop.state == F.ACTIVE


def test_our_unlock_on_their_farm():
    fop = F.Fop1(SCID, 0)
    farm = TheirFarm()
    farm.frame(TcFrame(SCID, 0, b"x", 100))
    assert farm.farm.state == their_farm.FarmState.LOCKOUT
    fop.directive(F.INITIATE_AD_WITH_UNLOCK, now=0)
    for f in fop.take_frames():
        farm.frame(over_the_air(f))
    assert farm.farm.state == their_farm.FarmState.OPEN
    fop.on_clcw(Clcw.unpack(farm.clcw()), 1)
    assert fop.state == F.ACTIVE
    fop.directive(F.TERMINATE_AD, now=2)
    fop.directive(F.INITIATE_AD_WITH_SET_VR, 9, now=2)
    for f in fop.take_frames():
        farm.frame(over_the_air(f))
    assert farm.farm.v_r == 9
    fop.on_clcw(Clcw.unpack(farm.clcw()), 3)
    assert fop.state == F.ACTIVE


# -- side by side -------------------------------------------------------------------------


def test_farms_agree_on_random_frame_sequences():
    rng = random.Random(2024)
    for _ in range(40):
        ours = our_farm.Farm1(0, 10)
        theirs = TheirFarm()
        for _ in range(60):
            r = rng.random()
            if r < 0.75:
                vr = ours.vr
                ns = (vr + rng.choice((0, 0, 0, 1, 2, 4, 5, -1, -3, -5, -6, 100))) & 0xFF
                if ours.state == our_farm.LOCKOUT and ns == vr:
                    continue  # ccsds-cop still buffers such a frame; the standard discards it
                frame = TcFrame(SCID, 0, b"%d" % ns, ns)
            elif r < 0.85:
                frame = TcFrame(SCID, 0, b"bd", 0, True)
            elif r < 0.93:
                frame = TcFrame(SCID, 0, UNLOCK, 0, True, True)
            else:
                frame = TcFrame(SCID, 0, set_vr_command(rng.randrange(256)), 0, True, True)
            ours.on_frame(frame)
            drain(ours)
            theirs.frame(frame)
            assert ours.clcw().pack() == theirs.clcw()
            assert ours.state == theirs.farm.state.value


def test_fops_agree_on_clcw_sequences():
    rng = random.Random(99)
    state_map = {s.value: s for s in their_fop.FopState}
    for _ in range(40):
        theirs = TheirFop(limit=rng.choice((1, 2, 3)), k=8)
        ours = F.Fop1(
            SCID, 0, window=8, t1=10000, transmission_limit=theirs.fop.transmission_limit
        )
        try:
            theirs.directive(D.INITIATE_AD_NO_CLCW)
            ours.directive(F.INITIATE_AD_NO_CLCW, now=0)
            for _ in range(30):
                if rng.random() < 0.4:
                    fdu = b"%d" % rng.randrange(1000)
                    if ours.ready:
                        a = ours.send_ad(fdu, 0) and ours.take_frames()
                        b = theirs.send(fdu)
                        assert [(f.seq, f.data) for f in a] == [(f.seq, f.data) for f in b]
                    continue
                if ours.state == F.INITIAL:
                    break
                # All or nothing acknowledged: ccsds-cop 0.1.2 empties its whole Sent_Queue on a
                # partial acknowledgement, so partial ones are compared in the loop tests only.
                nr = rng.choice((ours.nnr, ours.vs))
                c = Clcw(0, nr, retransmit=rng.random() < 0.3, wait=rng.random() < 0.1)
                a = [(f.seq, f.data) for f in (ours.on_clcw(c, 0) or ours.take_frames())]
                b = [(f.seq, f.data) for f in theirs.clcw(c.pack())]
                assert a == b
                assert theirs.fop.state == state_map[ours.state]
                assert (theirs.fop.v_s, theirs.fop.nn_r) == (ours.vs, ours.nnr)
        finally:
            theirs.close()
