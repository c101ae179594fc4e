"""M24512 I2C EEPROM (64 KiB, 128-byte pages, 16-bit addresses): reads and page writes."""

from obsw.compat import const

SIZE = const(65536)
PAGE = const(128)
_POLLS = const(400)


class EepromError(OSError):
    """The device did not acknowledge, or stayed busy after a write longer than allowed."""

    def __init__(self, msg, address=None):
        super().__init__(msg)
        self.address = address


class M24512:
    """One M24512 on an I2C bus (``machine.I2C``-like, see obsw.reconfig.hal)."""

    def __init__(self, i2c, address=0x50, polls=_POLLS):
        self.i2c = i2c
        self.address = address
        self.polls = polls

    def read(self, mem, n):
        if mem < 0 or mem + n > SIZE:
            raise ValueError("EEPROM read of %d bytes at 0x%X leaves 0..0x%X" % (n, mem, SIZE))
        return self.i2c.readfrom_mem(self.address, mem, n, addrsize=16)

    def write(self, mem, data):
        """Write ``data`` at ``mem``, split at page boundaries (a page write wraps inside its
        page), waiting for each internal write cycle by acknowledge polling."""
        if mem < 0 or mem + len(data) > SIZE:
            raise ValueError(
                "EEPROM write of %d bytes at 0x%X leaves 0..0x%X" % (len(data), mem, SIZE)
            )
        view = memoryview(data)
        i = 0
        while i < len(data):
            n = PAGE - ((mem + i) % PAGE)
            if n > len(data) - i:
                n = len(data) - i
            self.i2c.writeto_mem(self.address, mem + i, view[i : i + n], addrsize=16)
            self.wait_ready()
            i += n

    def wait_ready(self):
        """Poll until the device acknowledges its address again (write cycle over)."""
        for _ in range(self.polls):
            try:
                self.i2c.writeto(self.address, b"")
                return
            except OSError:
                pass
        raise EepromError("M24512 at 0x%02X still busy" % self.address, self.address)
