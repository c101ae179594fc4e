"""The core's error kinds (obsw.errors): every too-short error of every family takes
(what, needed, got), every length error (what, expected, got), with the same attributes and
message; unknown names are KeyErrors that name the closest known name."""

import unittest

from obsw.bits import BitsTooShortError
from obsw.cfdp.defs import CfdpError, PduTooShortError
from obsw.errors import UnknownNameError, closest, too_short, wrong_length
from obsw.frames.errors import FrameError, FrameLengthError, FrameTooShortError
from obsw.pus.packets import PusError, PusLengthError, PusTooShortError
from obsw.spacecan.encoding import ValueTooShortError
from obsw.spacecan.timeframes import CanFrameLengthError
from obsw.spp import BytesTooShortError, SppError
from obsw.timecode import TimeCodeError, TimeCodeTooShortError

TOO_SHORT = (  # class, its family, the unit of needed and got
    (FrameTooShortError, FrameError, "bytes"),
    (BytesTooShortError, SppError, "bytes"),
    (TimeCodeTooShortError, TimeCodeError, "bytes"),
    (PduTooShortError, CfdpError, "bytes"),
    (PusTooShortError, PusError, "bytes"),
    (ValueTooShortError, ValueError, "bytes"),
    (BitsTooShortError, ValueError, "bits"),
)
LENGTH = (
    (FrameLengthError, FrameError),
    (PusLengthError, PusError),
    (CanFrameLengthError, ValueError),
)


class TestKinds(unittest.TestCase):
    def test_every_too_short_error_takes_what_needed_got(self):
        for cls, family, unit in TOO_SHORT:
            e = cls("header", 6, 3)
            self.assertEqual((e.what, e.needed, e.got), ("header", 6, 3), cls.__name__)
            self.assertEqual(str(e), too_short("header", 6, 3, unit), cls.__name__)
            self.assertTrue(isinstance(e, family) and isinstance(e, ValueError), cls.__name__)

    def test_every_length_error_takes_what_expected_got(self):
        for cls, family in LENGTH:
            e = cls("frame", 8, 5)
            self.assertEqual((e.what, e.expected, e.got), ("frame", 8, 5), cls.__name__)
            self.assertTrue(isinstance(e, family) and isinstance(e, ValueError), cls.__name__)
        self.assertEqual(str(FrameLengthError("frame", 8, 5)), wrong_length("frame", 8, 5))

    def test_messages(self):
        self.assertEqual(too_short("CUC time", 7, 2), "CUC time too short: 2 bytes, needs 7")
        self.assertEqual(
            too_short("buffer", 12, 11, "bits"), "buffer too short: 11 bits, needs 12"
        )
        self.assertEqual(wrong_length("TC frame", 9, 10), "TC frame length: 10 bytes, expected 9")

    def test_a_pus_too_short_error_is_a_length_error(self):
        # the acceptance failure code of both is "invalid length" (PUS-C 6.1.4.3)
        self.assertTrue(isinstance(PusTooShortError("TC packet", 6, 3), PusLengthError))


class TestUnknownName(unittest.TestCase):
    def test_a_key_error_with_the_closest_name(self):
        known = ["SolarPanel.angle", "SolarPanel.speed", "Obc.uptime"]
        e = UnknownNameError("parameter", "SolarPanel.sped", known=known)
        self.assertTrue(isinstance(e, KeyError))
        self.assertEqual(e.suggestion, "SolarPanel.speed")
        self.assertEqual(
            str(e),
            "no parameter 'SolarPanel.sped' in the spacecraft database "
            "(did you mean 'SolarPanel.speed'?)",
        )
        self.assertEqual(e.args[0], str(e))

    def test_nothing_close_suggests_nothing(self):
        e = UnknownNameError("event", "zzz", where="the table", known=["SolarPanel.deployed"])
        self.assertIsNone(e.suggestion)
        self.assertEqual(str(e), "no event 'zzz' in the table")

    def test_closest(self):
        self.assertEqual(closest("max_dipol", ["max_dipole", "min_dipole", "coil"]), "max_dipole")
        self.assertEqual(closest("SPEED", ["speed"]), "speed")  # case does not count
        self.assertIsNone(closest("abc", []))
        self.assertIsNone(closest("abc", ["xyz"]))


if __name__ == "__main__":
    unittest.main()
