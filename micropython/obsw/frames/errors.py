"""Errors raised by the frame decoders: narrow ValueError subclasses that carry what they saw."""

from obsw.errors import too_short, wrong_length


class FrameError(ValueError):
    """Base of every decode error in obsw.frames."""


class FrameTooShortError(FrameError):
    """Fewer bytes than the structure needs (``obsw.errors``: the too-short kind)."""

    def __init__(self, what, needed, got):
        super().__init__(too_short(what, needed, got))
        self.what = what
        self.needed = needed
        self.got = got


class FrameLengthError(FrameError):
    """A length field or a configured length that does not match the bytes."""

    def __init__(self, what, expected, got):
        super().__init__(wrong_length(what, expected, got))
        self.what = what
        self.expected = expected
        self.got = got


class FrameHeaderError(FrameError):
    """A header field with a value the standard (or this channel's configuration) rules out."""

    def __init__(self, field, value, expected):
        super().__init__("%s is %r, expected %s" % (field, value, expected))
        self.field = field
        self.value = value
        self.expected = expected


class FecfError(FrameError):
    """Frame error control field does not match the CRC-16 of the frame."""

    def __init__(self, received, computed):
        super().__init__("FECF is 0x%04X, frame CRC is 0x%04X" % (received, computed))
        self.received = received
        self.computed = computed


class CltuError(FrameError):
    """A CLTU without start or tail sequence, or with an uncorrectable codeblock."""

    def __init__(self, msg, block=None):
        super().__init__(msg)
        self.block = block


class ControlCommandError(FrameError):
    """A Type-BC frame whose data is neither Unlock nor Set V(R)."""

    def __init__(self, data):
        super().__init__("control command %r is neither Unlock nor Set V(R)" % (bytes(data),))
        self.data = bytes(data)


class RsUncorrectableError(FrameError):
    """A Reed-Solomon codeblock (131.0-B) with more errors than its codewords can correct.

    ``codewords`` lists the interleaved codewords (0 to I-1) that failed; ``corrected`` the
    symbols corrected in each codeword (-1 where it failed); ``data`` the frame as received."""

    def __init__(self, codewords, corrected, data):
        super().__init__(
            "Reed-Solomon codeword %s uncorrectable (corrected per codeword: %s)"
            % (", ".join(str(w) for w in codewords), corrected)
        )
        self.codewords = codewords
        self.corrected = corrected
        self.data = data
