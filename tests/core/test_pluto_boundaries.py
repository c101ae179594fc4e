"""PLUTO's relational operators pinned at their boundaries: every operator on numbers, on
quantities (the same and converted units) and inside procedures, exactly at, one step below and
one step above the value compared with."""

import unittest

from obsw.pluto.evaluate import _cmp
from obsw.pluto.interp import Procedure, load
from obsw.pluto.system import SimulatedSystem, run_virtual
from obsw.pluto.units import Quantity

# op -> (below, at, above): the result of "x op 3.3" with x just below, at and just above it
EXPECTED = {
    "<": (True, False, False),
    "<=": (True, True, False),
    "=": (False, True, False),
    "!=": (True, False, True),
    ">=": (False, True, True),
    ">": (False, False, True),
}


class TestRelationalBoundaries(unittest.TestCase):
    def test_numbers(self):
        for op, want in EXPECTED.items():
            self.assertEqual(tuple(_cmp(op, x, 33) for x in (32, 33, 34)), want, op)
            self.assertEqual(tuple(_cmp(op, x, 3.3) for x in (3.2, 3.3, 3.4)), want, op)

    def test_quantities_in_the_same_unit(self):
        limit = Quantity(3.3, "V")
        for op, want in EXPECTED.items():
            got = tuple(_cmp(op, Quantity(v, "V"), limit) for v in (3.2, 3.3, 3.4))
            self.assertEqual(got, want, op)

    def test_quantities_in_other_units(self):
        limit = Quantity(3.3, "V")
        for op, want in EXPECTED.items():
            got = tuple(_cmp(op, Quantity(v, "mV"), limit) for v in (3299, 3300, 3301))
            self.assertEqual(got, want, op)

    def test_in_a_procedure(self):
        lines = []
        for i, op in enumerate(EXPECTED):
            for j, v in enumerate(("3.2 V", "3.3 V", "3.4 V")):
                lines.append("if %s %s 3.3 V then log %d; end if;" % (v, op, 10 * i + j))
        src = (
            "procedure\ninitiate and confirm step S\nmain\n%s\nend main\nend step;\n"
            "end procedure" % "\n".join(lines)
        )
        sim = SimulatedSystem({"clock_start": "2026-01-01T00:00:00Z"})
        p = Procedure(load(src), sim)
        p.start(sim.now)
        run_virtual(p, sim)
        want = [str(10 * i + j) for i, op in enumerate(EXPECTED) for j in range(3)
                if EXPECTED[op][j]]  # fmt: skip
        self.assertEqual(sim.logs, want)


if __name__ == "__main__":
    unittest.main()
