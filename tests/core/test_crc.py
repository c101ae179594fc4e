"""CRC-16/CCITT-FALSE and the CFDP checksum types, against catalogue check values."""

import unittest

from obsw import crc

CHECK = b"123456789"


def _bitwise_msb(data, width, poly, reg):
    # Shift-register definition straight from the generator polynomial, one bit at a time.
    top = 1 << (width - 1)
    mask = (1 << width) - 1
    for byte in data:
        reg ^= byte << (width - 8)
        for _ in range(8):
            reg = ((reg << 1) ^ poly) & mask if reg & top else (reg << 1) & mask
    return reg


class TestCatalogue(unittest.TestCase):
    def test_check_values(self):
        self.assertEqual(crc.crc16_ccitt(CHECK), 0x29B1)
        self.assertEqual(crc.crc32(CHECK), 0xCBF43926)
        self.assertEqual(crc.crc32c(CHECK), 0xE3069283)

    def test_pure_functions_give_check_values(self):
        for spec in (crc.CRC16_CCITT_FALSE, crc.CRC32_IEEE, crc.CRC32C_CASTAGNOLI):
            self.assertEqual(spec(CHECK), spec.check)

    def test_empty_input_gives_start_value(self):
        self.assertEqual(crc.crc16_ccitt(b""), 0xFFFF)
        self.assertEqual(crc.crc32(b""), 0)

    def test_pus_packet_error_control_residue(self):
        # ECSS-E-ST-70-41C annex B: appending the CRC makes the CRC of the whole zero.
        data = bytes(range(40))
        c = crc.crc16_ccitt(data)
        self.assertEqual(crc.crc16_ccitt(data + bytes([c >> 8, c & 0xFF])), 0)

    def test_ecss_syndrome_examples(self):
        # ECSS-E-ST-70-41C table B-1 style vectors for CRC-16/CCITT with all-ones preset.
        self.assertEqual(crc.crc16_ccitt(b"\x00\x00"), 0x1D0F)
        self.assertEqual(crc.crc16_ccitt(b"\x00\x00\x00"), 0xCC9C)
        self.assertEqual(crc.crc16_ccitt(b"\xab\xcd\xef\x01"), 0x04A2)
        self.assertEqual(crc.crc16_ccitt(b"\x14\x56\xf8\x9a\x00\x01"), 0x7FD5)

    def test_proximity1_matches_shift_register(self):
        for data in (CHECK, b"", b"\x00", b"\xff" * 7, bytes(range(256))):
            self.assertEqual(crc.crc32_proximity1(data), _bitwise_msb(data, 32, 0x00A00805, 0))
            self.assertEqual(crc.CRC32_PROXIMITY1(data), _bitwise_msb(data, 32, 0x00A00805, 0))

    def test_crc16_matches_shift_register(self):
        data = bytes(range(200))
        self.assertEqual(crc.crc16_ccitt(data), _bitwise_msb(data, 16, 0x1021, 0xFFFF))


class TestRunningValues(unittest.TestCase):
    def test_continuation_equals_whole(self):
        data = bytes(range(256)) * 3
        for f in (crc.crc16_ccitt, crc.crc32, crc.crc32c, crc.crc32_proximity1):
            self.assertEqual(f(data[100:], f(data[:100])), f(data))

    def test_update_form_agrees(self):
        # crc16_ccitt_update takes the register explicitly (binascii.crc_hqx on CPython)
        for s in (b"", CHECK, bytes(range(256))):
            self.assertEqual(crc.crc16_ccitt_update(s, 0xFFFF), crc.crc16_ccitt(s))
            self.assertEqual(crc.crc16_ccitt_update(s, 0xFFFF), crc.CRC16_CCITT_FALSE(s))
        self.assertEqual(crc.crc16_ccitt_update(CHECK[4:], crc.crc16_ccitt(CHECK[:4])), 0x29B1)

    def test_fast_path_agrees_with_pure(self):
        # On CPython the accelerated functions come from crcmod; on MicroPython they are the pure
        # ones. Either way both must agree on every input.
        pairs = (
            (crc.crc16_ccitt, crc.CRC16_CCITT_FALSE),
            (crc.crc32, crc.CRC32_IEEE),
            (crc.crc32c, crc.CRC32C_CASTAGNOLI),
            (crc.crc32_proximity1, crc.CRC32_PROXIMITY1),
        )
        samples = [b"", b"\x00", CHECK, bytes(range(256)), b"\xa5" * 1000]
        for fast, pure in pairs:
            for s in samples:
                self.assertEqual(fast(s), pure(s))
                self.assertEqual(fast(s[3:], fast(s[:3])), pure(s[3:], pure(s[:3])))

    def test_crc16_every_length_and_buffer_kind(self):
        # the pure CRC-16 takes one byte, two bytes or (CPython) bit planes per step depending
        # on the length and its parity; every way must equal the shift register, for any start
        # register and for bytes, bytearray and memoryview alike
        data = bytes((i * 89 + 7) & 0xFF for i in range(300))
        fns = [crc.crc16_ccitt_update, crc._crc16_bytes]
        if not crc.MICROPYTHON:
            fns += [crc._crc16_words]
        for n in list(range(0, 70)) + [127, 128, 255, 300]:
            s = data[:n]
            for reg in (0xFFFF, 0, 0x1D0F):
                want = _bitwise_msb(s, 16, 0x1021, reg)
                for f in fns:
                    self.assertEqual(f(s, reg), want)
                    self.assertEqual(f(bytearray(s), reg), want)
                    self.assertEqual(f(memoryview(b"x" + s)[1:], reg), want)

    def test_crc16_long_input(self):
        # longer than the bit planes cover at once (4 KiB): taken in chunks
        data = bytes((i * 31 + 5) & 0xFF for i in range(5001))
        want = _bitwise_msb(data, 16, 0x1021, 0xFFFF)
        self.assertEqual(crc.crc16_ccitt_update(data, 0xFFFF), want)
        self.assertEqual(crc.crc16_ccitt(data), want)
        self.assertEqual(crc.crc16_ccitt(data[4200:], crc.crc16_ccitt(data[:4200])), want)


class TestCfdpChecksums(unittest.TestCase):
    def test_modular_sums_aligned_words(self):
        self.assertEqual(crc.modular(b"\x01\x02\x03\x04\x05"), 0x06020304)
        self.assertEqual(crc.modular(b""), 0)
        self.assertEqual(crc.modular(b"\xff\xff\xff\xff\x00\x00\x00\x01"), 0)

    def test_modular_segments_in_any_order(self):
        data = bytes((i * 7) & 0xFF for i in range(3001))
        whole = crc.modular(data)
        parts = [(0, 5), (5, 1000), (1000, 1003), (1003, 3001)]
        total = 0
        for a, b in reversed(parts):
            total = crc.modular(data[a:b], a, total)
        self.assertEqual(total, whole)

    def test_file_checksum_each_kind(self):
        data = bytes(range(256)) * 5
        self.assertEqual(crc.checksum(crc.CHECKSUM_CRC32, data), crc.crc32(data))
        self.assertEqual(crc.checksum(crc.CHECKSUM_CRC32C, data), crc.crc32c(data))
        self.assertEqual(crc.checksum(crc.CHECKSUM_PROXIMITY1, data), crc.crc32_proximity1(data))
        self.assertEqual(crc.checksum(crc.CHECKSUM_MODULAR, data), crc.modular(data))
        self.assertEqual(crc.checksum(crc.CHECKSUM_NULL, data), 0)

    def test_file_checksum_incremental(self):
        data = bytes(range(251)) * 3
        for kind in (0, 1, 2, 3, 15):
            fc = crc.FileChecksum(kind)
            fc.update(data[:7]).update(data[7:500]).update(data[500:])
            self.assertEqual(fc.value, crc.checksum(kind, data))

    def test_unsupported_kind_is_typed_error(self):
        with self.assertRaises(crc.UnsupportedChecksumError) as ctx:
            crc.FileChecksum(9)
        self.assertEqual(ctx.exception.kind, 9)
        self.assertTrue(isinstance(ctx.exception, ValueError))
