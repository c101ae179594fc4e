"""Packets sealed with a packet error control computed here, from the CRC's definition, never
by the code under test: the PUS packet tests build their vectors with it."""


def crc_bitwise(data):
    """CRC-16/CCITT-FALSE from its definition: polynomial 0x1021, register preset to all ones."""
    reg = 0xFFFF
    for byte in data:
        reg ^= byte << 8
        for _ in range(8):
            reg = ((reg << 1) ^ 0x1021) & 0xFFFF if reg & 0x8000 else (reg << 1) & 0xFFFF
    return reg


def resealed(body):
    """``body`` (a packet without its PEC) with a valid PEC appended."""
    c = crc_bitwise(body)
    return bytes(body) + bytes((c >> 8, c & 0xFF))


def sealed(hexstr):
    """The packet written in hex (spaces allowed) without its PEC, with a valid PEC."""
    return resealed(bytes.fromhex(hexstr.replace(" ", "")))
