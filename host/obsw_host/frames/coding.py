"""A mission's space link from its ``frames`` section: the TM coding both ends use, the link
rates and the radio model of the simulation (``tm_coding``, ``downlink_bps``, ``uplink_bps``,
``radio``; keys and defaults in ``obsw_host.mission.defaults.FRAMES``)."""

from obsw.frames.sync import FrameSync
from obsw.frames.tm_coding import TmDecoder, TmEncoder

from obsw_host.mission import defaults

SCHEMES = ("none", "rs", "conv", "concatenated")
INTERLEAVE = (1, 2, 3, 4, 5, 8)


def _merged(section, key):
    out = dict(defaults.FRAMES[key])
    given = section.get(key)
    if isinstance(given, dict):
        for k, v in given.items():
            out[k] = dict(out[k], **v) if isinstance(out.get(k), dict) and isinstance(
                v, dict) else v  # fmt: skip
    return out


class LinkSettings:
    """The space link of one ``frames`` section (a dict, defaults filled in)."""

    def __init__(self, section=None):
        section = dict(section or {})
        self.frame_length = int(section.get("tm_frame_length", defaults.FRAMES["tm_frame_length"]))
        self.coding = _merged(section, "tm_coding")
        self.radio = _merged(section, "radio")
        self.downlink_bps = section.get("downlink_bps", defaults.FRAMES["downlink_bps"])
        self.uplink_bps = section.get("uplink_bps", defaults.FRAMES["uplink_bps"])
        self.tm_spill = int(section.get("tm_spill", defaults.FRAMES["tm_spill"]))

    @classmethod
    def of(cls, config):
        """The settings of a ``MissionConfig`` (or None: all defaults)."""
        return cls(config.section("frames") if config is not None else None)

    def _args(self):
        c = self.coding
        return (self.frame_length, c["scheme"], c["rs_e"], c["interleave"], c["randomize"])

    def encoder(self):
        """The OBC's ``TmEncoder``."""
        return TmEncoder(*self._args())

    def decoder(self):
        """A ground ``TmDecoder`` (one per link: each keeps its own lock)."""
        length = self.encoder().cadu_length - 4
        return TmDecoder(*self._args(), sync=FrameSync(length, **self.coding["sync"]),
                         count_symbols=True)  # fmt: skip

    @property
    def channel_length(self):
        """Octets on the air per TM frame (ASM and code included)."""
        return self.encoder().channel_length

    def describe(self):
        c = self.coding
        text = "TM %s" % c["scheme"]
        if c["scheme"] in ("rs", "concatenated"):
            text += " RS(255,%d) I=%d" % (255 - 2 * c["rs_e"], c["interleave"])
        text += ", %d-octet frames, %d octets on the air" % (
            self.frame_length,
            self.channel_length,
        )
        if self.downlink_bps:
            text += ", downlink %g bit/s" % self.downlink_bps
        return text

    def problems(self):
        """(JSON path, what is wrong and what was expected) of a combination the coder refuses
        (the schema checked each key alone)."""
        c = self.coding
        if c["scheme"] in ("rs", "concatenated"):
            k = 255 - 2 * c["rs_e"]
            most = k * c["interleave"]
            if self.frame_length > most:
                fits = [i for i in INTERLEAVE if k * i >= self.frame_length]
                hint = "interleave %d" % fits[0] if fits else "a tm_frame_length"
                return [(["frames", "tm_coding", "interleave"],
                         "%d-octet TM frames do not fit RS(255,%d) interleaved %d (%d octets "
                         "at most); expected %s or a shorter tm_frame_length"
                         % (self.frame_length, k, c["interleave"], most, hint))]  # fmt: skip
        try:
            self.encoder()
        except ValueError as e:
            return [(["frames", "tm_coding"], "%s; expected a combination the TM encoder "
                     "accepts" % e)]  # fmt: skip
        return []
