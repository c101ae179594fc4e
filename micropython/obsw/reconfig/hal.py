"""The hardware layer the reconfiguration module's logic is given (pyb on a board, a model here).

The core never touches a pin itself. A hardware layer is any object with the methods of `Hal`;
`boards/common/hal_pyb.py` drives a Pyboard, `obsw_sim.reconfig_hal` a simulated module,
and `obsw.reconfig.models.ModelHal` is an in-memory one for tests.
"""

from obsw.compat import const

NOMINAL = const(0)
REDUNDANT = const(1)
ROLE_NAMES = ("nominal", "redundant")

PORT_COM = const(0)  # UART to the COM module (CLTUs in, CADUs out)
PORT_OBC = const(1)  # UART to the OBC

CPDU_LINES = const(12)
CPDU_MASK = const(0xFFF)

# Why the controller last started (kept by the hardware layer, counted in the safeguard memory).
RESET_POWER = const(0)
RESET_WATCHDOG = const(1)
RESET_STUCK = const(2)  # the request-line supervisor (stuck CPDU_REQ)
RESET_SOFT = const(3)
RESET_NAMES = ("power", "watchdog", "stuck", "soft")


class Hal:
    """The interface, documented; methods raise until a hardware layer overrides them.

    Attributes: ``role`` (NOMINAL or REDUNDANT), ``i2c`` (``machine.I2C``-like:
    ``readfrom_mem(addr, mem, n, addrsize=16)``, ``writeto_mem(addr, mem, buf, addrsize=16)``,
    ``writeto(addr, buf)``), ``eeprom_addresses`` (I2C addresses of the M24512s),
    ``rtc_address`` (the DS3231).
    """

    role = NOMINAL
    i2c = None
    eeprom_addresses = (0x50, 0x51)
    rtc_address = 0x68

    def now_us(self):
        """Monotonic microseconds (never wrapping)."""
        raise NotImplementedError

    # CPDU: 12 data lines and the shared clock into two octal D flip-flops, the request lines
    def cpdu_data(self, bits):
        """Drive the 12 D lines with the low 12 bits of ``bits``."""
        raise NotImplementedError

    def cpdu_clock(self, level):
        raise NotImplementedError

    def cpdu_release(self):
        """Put the D lines and the clock in high impedance (the other controller may drive)."""
        raise NotImplementedError

    def cpdu_readback(self):
        """The latched outputs (12 bits) if the board reads them back, else None."""
        return None

    def req(self, level):
        """Own CPDU_REQ line."""
        raise NotImplementedError

    def other_req(self):
        """The other controller's CPDU_REQ line (True when high)."""
        raise NotImplementedError

    def alive(self, level):
        """Own alive line, toggled by the main loop; the other controller watches it."""

    def other_alive(self):
        """The other controller's alive line: its level, or a count of its edges (anything
        that changes when the line moves); None if not wired."""
        return None

    def wdi(self, level):
        """TPS3813 WDI input."""
        raise NotImplementedError

    # buses
    def can_recv(self, bus):
        """One frame from CAN bus 0 (A) or 1 (B) as (can_id, data), or None."""
        return None

    def can_send(self, bus, can_id, data):
        """Queue a frame; False if it could not be sent (the node is told: tx_error)."""
        raise NotImplementedError

    def uart_read(self, port):
        """Bytes waiting on PORT_COM or PORT_OBC (b"" if none)."""
        return b""

    def uart_write(self, port, data):
        raise NotImplementedError

    # life cycle
    def reset_cause(self):
        return RESET_POWER

    def reset(self):
        """Restart this controller (never returns on a board)."""
        raise NotImplementedError

    def idle(self, ms):
        """Wait up to ``ms`` milliseconds for something to do."""
