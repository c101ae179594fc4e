"""PLUTO reads engineering values: a calibrated raw attribute comes with its engineering unit,
an enumerated one as its label; a procedure compares them in engineering units."""

import unittest

from obsw.il.clock import SimClock
from obsw.il.interface import DATA, Attribute, Interface
from obsw.il.node import Node
from obsw.pluto.il_system import IlSystem
from obsw.pluto.interp import Procedure, load
from obsw.pluto.names import ParameterError
from obsw.pluto.units import Quantity
from obsw.pus.sdb import loads

SDB = """{"components": [{"name": "Coil", "attributes": [
  {"name": "temp", "parameter": 1, "type": "uint16", "unit": "degC",
   "calibration": {"spline": [[0, -40.0], [1000, 10.0], [4000, 85.0]]}},
  {"name": "mode", "parameter": 2, "type": "enum8", "enumeration": {"0": "OFF", "1": "ON"}},
  {"name": "count", "parameter": 3, "type": "uint16"}
]}]}"""

COIL = Interface(
    "Coil",
    0x60,
    [
        Attribute("temp", 1, DATA, type="uint16"),
        Attribute("mode", 2, DATA, type="uint8"),
        Attribute("count", 3, DATA, type="uint16"),
    ],
)


class Coil:
    def __init__(self):
        self.temp = 2500  # raw counts: 47.5 degC
        self.mode = 1
        self.count = 7


def world():
    clock = SimClock(1000.0)
    node = Node("obc", clock)
    coil = Coil()
    node.provide(COIL, coil)
    out = []
    system = IlSystem(node, loads(SDB), timeout=0.5, on_output=lambda k, t: out.append(t))
    return clock, node, coil, system, out


class TestEngineeringValues(unittest.TestCase):
    def test_get_gives_engineering_values(self):
        clock, node, coil, system, out = world()
        v = system.get("temp of Coil")
        self.assertTrue(isinstance(v, Quantity))
        self.assertAlmostEqual(v.value, 47.5)
        self.assertEqual(v.unit, "degC")
        self.assertEqual(system.get("mode of Coil"), "ON")
        self.assertEqual(system.get("count of Coil"), 7)  # no calibration: the value itself
        self.assertEqual(system.describe("temp of Coil"), ("parameter", "r", "degC"))
        self.assertEqual(system.describe("mode of Coil"), ("parameter", "s", None))

    def test_raw_outside_the_calibration_is_a_read_error(self):
        clock, node, coil, system, out = world()
        coil.temp = 5000
        self.assertRaises(ParameterError, system.get, "temp of Coil")

    def test_a_procedure_compares_in_engineering_units(self):
        clock, node, coil, system, out = world()
        src = (
            "procedure main initiate and confirm step S main "
            'if (temp of Coil > 40 degC) AND (mode of Coil = "ON") then '
            'log "hot"; else log "ok"; end if; '
            "end main end step; end main end procedure"
        )
        p = Procedure(load(src, system), system, poll=0.5)
        p.start(clock.now())
        for _ in range(20):
            node.poll()
            w = p.run(clock.now())
            if p.state != "running" or w is None:
                break
        self.assertEqual(out, ["hot"])


if __name__ == "__main__":
    unittest.main()
