"""Raw <-> engineering values: calibrations both ways, labels, ranges, limits as raw limits."""

import unittest

from obsw.pus.calibration import (
    CalibrationError,
    NotInvertibleError,
    Values,
    calibration,
    enumeration,
    limits,
)
from obsw.pus.fields import field
from obsw.pus.sdb import SdbError, loads

U16 = field(3, 12)
I16 = field(4, 12)
F32 = field(5, 1)


class TestPolynomial(unittest.TestCase):
    def test_degree_one_both_ways(self):  # binary-exact numbers: the same on a board's floats
        c = calibration({"polynomial": [-50.0, 0.0625]})
        self.assertEqual(c.engineering(1400), 37.5)
        self.assertEqual(c.raw(37.5), 1400.0)

    def test_xtce_terms(self):
        c = calibration({"polynomial": [{"coefficient": 2.0, "exponent": 1}]})
        self.assertEqual(c.coefficients, [0, 2.0])
        self.assertAlmostEqual(c.engineering(3), 6.0)

    def test_higher_degree_has_no_inverse(self):
        c = calibration({"polynomial": [0, 0, 1]})
        self.assertAlmostEqual(c.engineering(3), 9.0)
        self.assertRaises(NotInvertibleError, c.raw, 9.0)
        self.assertRaises(NotInvertibleError, calibration({"polynomial": [5]}).raw, 5)

    def test_malformed(self):
        for bad in ({"polynomial": []}, {"polynomial": ["a"]}, {"poly": [1]}, [1, 2], 3):
            self.assertRaises(CalibrationError, calibration, bad)
        terms = [{"coefficient": 1, "exponent": 1}, {"coefficient": 2, "exponent": 1}]
        self.assertRaises(CalibrationError, calibration, {"polynomial": terms})


class TestSpline(unittest.TestCase):
    def test_linear_interpolation_both_ways(self):
        c = calibration({"spline": [[0, -40.0], [1000, 10.0], [4000, 85.0]]})
        self.assertAlmostEqual(c.engineering(500), -15.0)
        self.assertAlmostEqual(c.engineering(2500), 47.5)
        self.assertAlmostEqual(c.raw(47.5), 2500.0)
        self.assertAlmostEqual(c.raw(-40.0), 0.0)

    def test_outside_the_points(self):
        c = calibration({"spline": [[0, 0.0], [10, 100.0]]})
        self.assertRaises(CalibrationError, c.engineering, 11)
        self.assertRaises(CalibrationError, c.raw, 101.0)
        e = calibration({"spline": [[0, 0.0], [10, 100.0]], "extrapolate": True})
        self.assertAlmostEqual(e.engineering(11), 110.0)
        self.assertAlmostEqual(e.raw(-10.0), -1.0)

    def test_xtce_points_and_order_zero(self):
        c = calibration(
            {"spline": [{"raw": 10, "calibrated": 1.0}, {"raw": 0, "calibrated": 0.0}], "order": 0}
        )
        self.assertEqual(c.points, [(0, 0.0), (10, 1.0)])
        self.assertEqual(c.engineering(5), 0.0)
        self.assertEqual(c.engineering(10), 1.0)
        self.assertRaises(NotInvertibleError, c.raw, 0.5)

    def test_not_monotonic_has_no_inverse(self):
        c = calibration({"spline": [[0, 0.0], [5, 10.0], [10, 0.0]]})
        self.assertAlmostEqual(c.engineering(7.5), 5.0)
        self.assertRaises(NotInvertibleError, c.raw, 5.0)

    def test_malformed(self):
        for bad in (
            {"spline": [[0, 1]]},
            {"spline": [[0, 1], [0, 2]]},
            {"spline": [[0, 1], [1]]},
            {"spline": [[0, 1], [1, 2]], "order": 3},
        ):
            self.assertRaises(CalibrationError, calibration, bad)


class TestValues(unittest.TestCase):
    def test_enumeration_shapes(self):
        self.assertEqual(enumeration({"0": "OFF", "1": "ON"}), {0: "OFF", 1: "ON"})
        self.assertEqual(enumeration([{"value": 2, "label": "SAFE"}]), {2: "SAFE"})
        twice = [{"value": 1, "label": "A"}, {"value": 1, "label": "B"}]
        for bad in ({"x": "A"}, {"0": ""}, twice):
            self.assertRaises(CalibrationError, enumeration, bad)

    def test_labels_both_ways(self):
        v = Values(field(2, 8), {"enumeration": {"0": "OFF", "1": "ON"}})
        self.assertEqual(v.engineering(1), "ON")
        self.assertEqual(v.engineering(7), 7)  # no label: the raw value
        self.assertEqual(v.to_raw("OFF"), 0)
        self.assertEqual(v.to_raw(1), 1)
        self.assertRaises(CalibrationError, v.to_raw, "DIM")

    def test_integer_raw_is_rounded(self):
        v = Values(U16, {"calibration": {"polynomial": [-50, 0.05]}})
        self.assertEqual(v.to_raw(20.02), 1400)
        self.assertEqual(v.to_raw(20.04), 1401)

    def test_range_in_engineering_units(self):
        v = Values(U16, {"calibration": {"polynomial": [-50, 0.05]}, "range": [-10, 40]})
        self.assertIsNone(v.out_of_range(1400))  # 20 degC
        self.assertIn("outside", v.out_of_range(2000))  # 50 degC
        self.assertIn("outside", v.out_of_range(0))  # -50 degC
        self.assertIsNone(Values(F32, {"range": [None, 3]}).out_of_range(-1e9))
        self.assertIn("is not a number", Values(F32, {"range": [0, 3]}).out_of_range("fast"))

    def test_raw_limits_rounded_inwards(self):
        v = Values(U16, {"calibration": {"polynomial": [-50, 0.05]}})
        self.assertEqual(v.raw_limits(-10.01, 40.01), (800, 1800, False))
        # 40 degC is raw 1800 less a rounding error (more in single precision): still 1800
        low, high, _ = v.raw_limits(-10.0, 40.0)
        self.assertEqual((low, high), (800, 1800))

    def test_range_edges_survive_rounding(self):
        v = Values(U16, {"calibration": {"polynomial": [-50, 0.05]}, "range": [-10, 40]})
        self.assertIsNone(v.out_of_range(800))
        self.assertIsNone(v.out_of_range(1800))
        self.assertIn("outside", v.out_of_range(1801))

    def test_raw_limits_of_a_decreasing_calibration_swap(self):
        v = Values(I16, {"calibration": {"polynomial": [100, -1]}})
        self.assertEqual(v.raw_limits(10, 90), (10, 90, True))
        f = Values(F32, {})
        self.assertEqual(f.raw_limits(0.5, 15.0), (0.5, 15.0, False))

    def test_limits_shape(self):
        self.assertEqual(limits({"warning": [1, 10]}), {"warning": (1, 10)})
        for bad in ({"warning": [10, 1]}, {"yellow": [1, 2]}, {"warning": 3}, {}):
            self.assertRaises(CalibrationError, limits, bad)

    def test_shapes_that_do_not_fit_the_type(self):
        self.assertRaises(CalibrationError, Values, field(8, 0), {"range": [0, 1]})
        self.assertRaises(CalibrationError, Values, F32, {"enumeration": {"0": "A"}})


DB = """{"components": [{"name": "Coil", "attributes": [
  {"name": "temp", "parameter": 1, "type": "uint16", "unit": "degC", "raw_unit": "count",
   "calibration": {"polynomial": [-50, 0.0625]}, "range": [-40, 80],
   "limits": {"warning": [-10, 40]}},
  {"name": "mode", "parameter": 2, "type": "enum8", "enumeration": {"0": "OFF", "1": "ON"}}
]}]}"""


class TestDatabase(unittest.TestCase):
    def test_parameter_values(self):
        db = loads(DB)
        temp = db.parameter("Coil.temp")
        self.assertEqual((temp.unit, temp.raw_unit), ("degC", "count"))
        self.assertEqual(temp.engineering(1400), 37.5)
        self.assertEqual(temp.to_raw(37.5), 1400)
        self.assertIn("outside", temp.out_of_range(3000))
        self.assertEqual(db.parameter("Coil.mode").engineering(1), "ON")

    def test_bad_entries_are_database_errors(self):
        bad = DB.replace('"range": [-40, 80]', '"range": [80, -40]')
        self.assertRaises(SdbError, loads, bad)
        bad = DB.replace('"polynomial": [-50, 0.0625]', '"polynomial": "x"')
        self.assertRaises(SdbError, loads, bad)


if __name__ == "__main__":
    unittest.main()
