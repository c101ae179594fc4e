"""A mission component as a plug-in: a magnetorquer (docs/topology.md shows this file)."""

from obsw.il.errors import ComponentError
from obsw.il.interface import DATA, INFO, Attribute, Event, Interface, Operation

MAGNETORQUER = Interface(
    "Magnetorquer",
    0x61,
    [
        Attribute("dipole", 1, DATA, type="f32", unit="A m2", description="commanded dipole"),
        Operation("fire", 2, ("dipole",), returns="f32", description="set the dipole"),
        Event("saturated", 3, INFO, fields=("dipole",)),
    ],
    description="a three-axis magnetorquer (one axis shown)",
)


class Torquer:
    def __init__(self, coils=1, limit=0.2):
        self.coils = coils
        self.limit = limit
        self.dipole = 0.0
        self.il = None

    def il_bind(self, provider):
        self.il = provider

    def fire(self, dipole):
        if not -1.0 <= dipole <= 1.0:
            raise ComponentError("OUT_OF_RANGE", "dipole %s beyond 1 A m2" % dipole)
        if abs(dipole) > self.limit:
            self.il.emit("saturated", {"dipole": dipole})
            dipole = self.limit if dipole > 0 else -self.limit
        self.il.update("dipole", float(dipole))
        return self.dipole
