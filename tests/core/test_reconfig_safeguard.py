"""Safeguard memory: SECDED coding, M24512 page writes, and records that survive thousands of
resets injected at random points of their writes and bit errors on the I2C bus."""

import unittest

from obsw.reconfig import ecc
from obsw.reconfig.dekker_sim import Rng
from obsw.reconfig.eeprom import M24512, EepromError
from obsw.reconfig.models import M24512Model, SimI2C, SimReset
from obsw.reconfig.safeguard import RecordError, Safeguard


def rig(seed=1, gap=0, devices=2):
    i2c = SimI2C(seed, gap)
    models = []
    for k in range(devices):
        m = M24512Model()
        i2c.devices[0x50 + k] = m
        models.append(m)
    return i2c, models, [M24512(i2c, 0x50 + k) for k in range(devices)]


class TestEcc(unittest.TestCase):
    def test_round_trip_and_every_single_error_corrected(self):
        data = bytes(range(3, 43))
        coded = ecc.encode(data)
        self.assertEqual(len(coded), 45)
        out, fixed = ecc.decode(coded)
        self.assertEqual(bytes(out), data)
        self.assertEqual(fixed, 0)
        for bit in range(9 * 8):
            bad = bytearray(coded[:9])
            bad[bit >> 3] ^= 0x80 >> (bit & 7)
            out, fixed = ecc.decode(bad)
            self.assertEqual(bytes(out), data[:8])
            self.assertEqual(fixed, 1)

    def test_double_errors_detected(self):
        coded = ecc.encode(b"ABCDEFGH")
        rng = Rng(3)
        for _ in range(300):
            a = rng.below(72)
            b = rng.below(72)
            if a == b:
                continue
            bad = bytearray(coded)
            bad[a >> 3] ^= 0x80 >> (a & 7)
            bad[b >> 3] ^= 0x80 >> (b & 7)
            with self.assertRaises(ecc.EccError):
                ecc.decode(bad)


class TestEeprom(unittest.TestCase):
    def test_write_split_at_pages_and_read(self):
        i2c, models, devs = rig()
        data = bytes(range(200))
        devs[0].write(100, data)
        self.assertEqual(bytes(devs[0].read(100, 200)), data)
        self.assertEqual(models[0].mem[99], 0xFF)

    def test_page_write_wraps_inside_the_page(self):
        m = M24512Model()
        m.write(120, bytes(range(16)))
        self.assertEqual(bytes(m.mem[120:128]), bytes(range(8)))
        self.assertEqual(bytes(m.mem[0:8]), bytes(range(8, 16)))

    def test_busy_device_times_out(self):
        i2c, models, devs = rig()
        models[0].busy_polls = 1000
        with self.assertRaises(EepromError):
            devs[0].write(0, b"x")
        with self.assertRaises(ValueError):
            devs[0].read(65530, 10)


class TestRecords(unittest.TestCase):
    def test_write_read_and_capacity(self):
        i2c, models, devs = rig()
        sg = Safeguard(devs, records=4)
        self.assertEqual(sg.capacity, 100)
        self.assertIsNone(sg.read(2))
        self.assertEqual(sg.write(2, b"hello"), 2)
        self.assertEqual(sg.write(2, b"world!"), 2)
        self.assertEqual(Safeguard(devs, records=4).read(2), b"world!")
        with self.assertRaises(RecordError):
            sg.write(2, bytes(101))
        with self.assertRaises(RecordError):
            sg.read(4)

    def test_repair_of_a_lost_device_copy(self):
        i2c, models, devs = rig()
        sg = Safeguard(devs, records=2)
        sg.write(0, b"one")
        sg.write(0, b"two")
        models[1].mem[0:256] = b"\xff" * 256  # device 2 lost both slots
        sg2 = Safeguard(devs, records=2)
        self.assertEqual(sg2.read(0), b"two")
        self.assertEqual(sg2.counters["repairs"], 1)
        models[0].mem[0:256] = b"\xff" * 256  # now device 1 dies: device 2 was repaired
        self.assertEqual(Safeguard(devs, records=2).read(0), b"two")

    def test_one_device_is_enough(self):
        i2c, models, devs = rig(devices=1)
        sg = Safeguard(devs)
        sg.write(7, b"solo")
        self.assertEqual(Safeguard(devs).read(7), b"solo")

    def test_cell_errors_corrected_and_scrubbed(self):
        i2c, models, devs = rig()
        sg = Safeguard(devs, records=1)
        sg.write(0, b"keep me")
        for m in models:
            for page in (0, 1):
                m.mem[page * 128 + 3] ^= 0x10
        sg2 = Safeguard(devs, records=1)
        self.assertEqual(sg2.read(0), b"keep me")
        self.assertTrue(sg2.counters["corrected"] > 0)

    def test_resets_and_bus_errors_never_lose_the_last_record(self):
        # Thousands of writes, each hit by a reset at a random transfer with probability 1/2,
        # on a bus that flips about one bit in 20000: every read after a reset must return
        # the last completed record or the one being written, never anything older or broken.
        i2c, models, devs = rig(seed=7, gap=20000)
        rng = Rng(99)
        sg = Safeguard(devs, records=3)
        last = [None, None, None]
        resets = 0
        olds = news = 0
        for n in range(2500):
            k = rng.below(3)
            payload = bytes([n & 0xFF, n >> 8]) + bytes(
                rng.below(256) for _ in range(rng.below(99))
            )
            if rng.below(2):
                i2c.reset_in = rng.below(4)
            try:
                sg.write(k, payload)
                i2c.reset_in = None
                last[k] = payload
                continue
            except SimReset:
                resets += 1
            sg = Safeguard(devs, records=3)  # the controller boots again
            got = sg.read(k)
            self.assertTrue(got == last[k] or got == payload)
            if got == payload:
                news += 1
                last[k] = payload
            else:
                olds += 1
            for j in range(3):
                self.assertEqual(sg.read(j), last[j])
        self.assertTrue(resets > 1000)
        self.assertTrue(olds > 100 and news > 100)
        self.assertTrue(i2c.flipped > 100)


class TestDecodeLengths(unittest.TestCase):
    def test_bytes_of_the_wrong_length_are_a_record_error(self):
        _, _, devices = rig()
        sg = Safeguard(devices)
        n = sg.blocks * ecc.CODED
        for raw in (b"", b"\x00" * (n - 1), b"\x00" * (n + 1)):
            with self.assertRaises(RecordError):
                sg.decode(0, raw)
        self.assertIsNone(sg.decode(0, b"\xff" * n))  # the right length, no valid copy
        good = sg.encode(0, 5, b"abc")
        self.assertEqual(sg.decode(0, good)[:2], (5, b"abc"))
