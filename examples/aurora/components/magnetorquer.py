"""Aurora-1's magnetorquer: three coils whose dipole detumbles the spacecraft (simulated).

A mission component plug-in (docs/mission.md, "Components"): ``MAGNETORQUER`` is its
interaction-layer interface and ``Magnetorquer`` implements it; ``mission.json`` names this
file in ``components`` and runs it in a process of its own.
"""

from obsw.il.errors import ComponentError
from obsw.il.interface import (
    CONFIGURATION,
    DATA,
    INFO,
    MEDIUM,
    Attribute,
    Event,
    Interface,
    Operation,
)

MAGNETORQUER = Interface(
    "Magnetorquer",
    0x61,
    [
        Attribute("dipole_x", 1, DATA, type="f32", unit="A.m^2", description="commanded dipole"),
        Attribute("dipole_y", 2, DATA, type="f32", unit="A.m^2"),
        Attribute("dipole_z", 3, DATA, type="f32", unit="A.m^2"),
        Attribute("coil_current", 4, DATA, type="i16", description="raw ADC counts"),
        Attribute("coil_temp", 5, DATA, type="u16", description="raw thermistor counts"),
        Attribute("enabled", 6, DATA, type="bool"),
        Attribute(
            "mode",
            7,
            CONFIGURATION,
            type="u8",
            description="0 off, 1 detumble, 2 pointing, 3 degauss",
        ),  # fmt: skip
        Attribute("duty", 8, CONFIGURATION, type="i8", description="PWM duty, percent"),
        Attribute("on_time", 9, DATA, type="u32", unit="s"),
        Attribute("energy", 10, DATA, type="f64", unit="J"),
        Attribute("pulses", 11, DATA, type="u64"),
        Attribute("max_dipole", 12, CONFIGURATION, type="f32", unit="A.m^2"),
        Attribute("label", 13, DATA, type="str"),
        Operation(
            "set_dipole",
            20,
            ("x", "y", "z"),
            returns="f32",
            description="command a dipole (A.m^2 per axis); returns its magnitude",
        ),  # fmt: skip
        Operation("enable", 21, ()),
        Operation("disable", 22, ()),
        Operation("degauss", 23, (), asynchronous=True, description="demagnetise the cores"),
        Event("saturated", 30, MEDIUM, fields=("axis", "requested")),
        Event("degaussed", 31, INFO, fields=("cycles",)),
    ],
    description="three-axis magnetorquer",
)

RAW_PER_MA = 8  # coil current ADC counts per mA
RAW_AT_0C = 1365  # thermistor counts at 0 degC (the database calibrates them)


class Magnetorquer:
    """The magnetorquer's implementation (simulated coils)."""

    def __init__(self, max_dipole=0.2, label="MTQ-A"):
        self.dipole_x = self.dipole_y = self.dipole_z = 0.0
        self.coil_current = 0
        self.coil_temp = RAW_AT_0C + 4 * 21  # about 21 degC
        self.enabled = False
        self._mode = 0
        self._duty = 0
        self.on_time = 0
        self.energy = 0.0
        self.pulses = 0
        self._max = float(max_dipole)
        self.label = label
        self.il = None

    def il_bind(self, provider):
        self.il = provider

    @property
    def mode(self):
        return self._mode

    @mode.setter
    def mode(self, value):
        if value not in (0, 1, 2, 3):
            raise ValueError("mode must be 0 off, 1 detumble, 2 pointing or 3 degauss", value)
        self._mode = int(value)

    @property
    def duty(self):
        return self._duty

    @duty.setter
    def duty(self, value):
        if not -100 <= value <= 100:
            raise ValueError("duty must be in [-100, 100] percent", value)
        self._duty = int(value)

    @property
    def max_dipole(self):
        return self._max

    @max_dipole.setter
    def max_dipole(self, value):
        if not 0 < value <= 0.5:
            raise ValueError("max_dipole must be in (0, 0.5] A.m^2", value)
        self._max = float(value)

    def enable(self):
        self.il.update("enabled", True)
        return True

    def disable(self):
        self.set_dipole(0.0, 0.0, 0.0)
        self.il.update("enabled", False)
        return True

    def set_dipole(self, x, y, z):
        if not self.enabled:
            raise ComponentError("DISABLED", "enable the magnetorquer before commanding it")
        for axis, value in (("x", x), ("y", y), ("z", z)):
            if abs(value) > self._max:
                self.il.emit("saturated", {"axis": axis, "requested": float(value)})
                raise ComponentError(
                    "SATURATED", "dipole %s = %s beyond %s A.m^2" % (axis, value, self._max)
                )
        for axis, value in (("x", x), ("y", y), ("z", z)):
            self.il.update("dipole_" + axis, float(value))
        magnitude = (x * x + y * y + z * z) ** 0.5
        self.il.update("coil_current", int(magnitude / self._max * 250 * RAW_PER_MA))
        self.il.update("pulses", self.pulses + 1)
        return magnitude

    def degauss(self, job):
        for cycle in (1, 2, 3, 4):  # alternating, decaying pulses on every axis
            job.update({"cycle": cycle, "of": 4})
        for axis in "xyz":
            self.il.update("dipole_" + axis, 0.0)
        self.il.update("coil_current", 0)
        self.il.emit("degaussed", {"cycles": 4})
        job.succeed("degaussed")
