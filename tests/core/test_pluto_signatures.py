"""Activity signatures: argument names, types and units declared in the spacecraft database (or
a simulated system's description), checked when a procedure loads; each error names the
activity and the argument."""

import unittest

from obsw.il.clock import SimClock
from obsw.il.interface import Interface, Operation
from obsw.il.node import Node
from obsw.pluto.checker import PlutoReferenceError, PlutoTypeError
from obsw.pluto.il_system import IlSystem
from obsw.pluto.interp import Procedure, load
from obsw.pluto.names import Catalog
from obsw.pluto.system import SimulatedSystem, argument_code, run_virtual
from obsw.pus.sdb import Sdb, SdbError

T0 = 0.0  # the IL clock near the epoch: exact in a board's single-precision floats

SDB = {
    "components": [
        {
            "name": "CpduN",
            "attributes": [{"name": "state", "parameter": 1, "type": "uint8"}],
            "operations": [
                {"name": "set_state_bits",
                 "arguments": [{"name": "state", "type": "uint8"},
                               {"name": "mask", "type": "uint8"}]},
                {"name": "pulse",
                 "arguments": [{"name": "line", "type": "uint8"},
                               {"name": "width", "type": "float32", "unit": "s"}]},
                {"name": "label", "arguments": [{"name": "text", "type": "string"},
                                                {"name": "armed", "type": "bool"},
                                                {"name": "anything"}]},
                {"name": "reset", "arguments": []},
                {"name": "flush"},
            ],
        }
    ]
}  # fmt: skip


class Cpdu:
    def __init__(self):
        self.calls = []

    def set_state_bits(self, state, mask):
        self.calls.append(("set_state_bits", state, mask))

    def pulse(self, line, width):
        self.calls.append(("pulse", line, width))

    def label(self, text, armed, anything):
        self.calls.append(("label", text, armed, anything))

    def reset(self):
        self.calls.append(("reset",))


CPDU = Interface(
    "CpduN",
    0x51,
    [
        Operation("set_state_bits", 2, ("state", "mask")),
        Operation("pulse", 3, ("line", "width")),
        Operation("label", 4, ("text", "armed", "anything")),
        Operation("reset", 5, ()),
    ],
)


def procedure(main):
    return (
        "procedure main initiate and confirm step S main %s end main end step; "
        "end main end procedure" % main
    )


def system():
    node = Node("obc", SimClock(T0))
    cpdu = Cpdu()
    node.provide(CPDU, cpdu)
    return IlSystem(node, SDB), cpdu


class TestDeclared(unittest.TestCase):
    def test_database_gives_the_signature(self):
        ops = Sdb(SDB).operations
        self.assertEqual(ops["CpduN.pulse"].signature,
                         [("line", "uint8", None), ("width", "float32", "s")])  # fmt: skip
        self.assertEqual(ops["CpduN.pulse"].arguments, [("line", None), ("width", "s")])
        self.assertEqual(ops["CpduN.reset"].signature, [])
        self.assertIsNone(ops["CpduN.flush"].signature)  # arguments not declared: any
        s, _ = system()
        self.assertEqual(s.signature("pulse of CpduN"), [("line", "u", None), ("width", "r", "s")])
        self.assertEqual(s.signature("set state bits of Cpdu N")[0], ("state", "u", None))
        self.assertIsNone(s.signature("state of CpduN"))  # a parameter, no activity
        self.assertIsNone(s.signature("flush of CpduN"))
        self.assertIsNone(Catalog(interfaces=[CPDU]).find("pulse of CpduN")[6])

    def test_type_names(self):
        for t, code in (("uint16", "u"), ("int8", "i"), ("float64", "r"), ("bool", "b"),
                        ("string", "s"), ("unsigned integer", "u"), ("relative time", "rt"),
                        ("absolute time", "a"), ("Boolean", "b"), ([3, 4], "u"), ([5, 1], "r"),
                        (None, "?"), ("enum8", "?")):  # fmt: skip
            self.assertEqual(argument_code(t), code)

    def test_database_refuses_bad_declarations(self):
        def refused(args, *words):
            doc = {
                "components": [{"name": "C", "operations": [{"name": "op", "arguments": args}]}]
            }
            with self.assertRaises(SdbError) as c:
                Sdb(doc)
            for w in words:
                self.assertIn(w, str(c.exception))

        refused([{"name": "a", "type": "uint7"}], "operation C.op, argument a", "uint7")
        refused([{"name": "a"}, {"name": "a"}], "operation C.op declares argument a twice")


class TestLoadTime(unittest.TestCase):
    def rejected(self, main, cls, msg):
        s, _ = system()
        with self.assertRaises(cls) as c:
            load(procedure(main), s)
        self.assertEqual(c.exception.msg, msg)

    def test_well_formed_calls_load_and_run(self):
        s, cpdu = system()
        p = Procedure(load(procedure(
            "initiate and confirm set_state_bits of CpduN with arguments mask := 0xFF,"
            " state := 5 end with; initiate and confirm pulse of CpduN with arguments 3,"
            ' 2 min end with; initiate and confirm label of CpduN with arguments'
            ' text := "x", armed := TRUE, anything := 2.5 V end with;'
            " initiate and confirm reset of CpduN;")), s, poll=0.5)  # fmt: skip
        p.start(T0)
        for _ in range(20):
            s.node.poll()
            if p.run(s.node.clock.now()) is None:
                break
            s.node.clock.advance(0.5)
        self.assertEqual(p.outcome, "confirmed")
        self.assertEqual(cpdu.calls, [("set_state_bits", 5, 255), ("pulse", 3, 120),
                                      ("label", "x", True, 2.5), ("reset",)])  # fmt: skip

    def test_unknown_argument(self):
        self.rejected(
            "initiate and confirm set_state_bits of CpduN with arguments state := 1, mask := 1,"
            " gain := 2 end with;", PlutoReferenceError,
            "activity set_state_bits of CpduN has no argument gain (takes: state,"
            " mask)")  # fmt: skip

    def test_missing_argument(self):
        self.rejected(
            "initiate set_state_bits of CpduN with arguments state := 1 end with;",
            PlutoTypeError,
            "activity set_state_bits of CpduN needs argument mask (takes: state,"
            " mask)")  # fmt: skip
        self.rejected(
            "initiate and confirm reset of CpduN with arguments 1 end with;", PlutoTypeError,
            "activity reset of CpduN takes 0 arguments (none), got 1")  # fmt: skip

    def test_wrong_type(self):
        self.rejected(
            'initiate and confirm set_state_bits of CpduN with arguments state := "on",'
            " mask := 1 end with;", PlutoTypeError,
            'activity set_state_bits of CpduN: argument state takes an unsigned integer,'
            ' got "on": types string and unsigned integer differ')  # fmt: skip
        self.rejected(
            "initiate and confirm set_state_bits of CpduN with arguments state := 1.5,"
            " mask := 1 end with;", PlutoTypeError,
            "activity set_state_bits of CpduN: argument state takes an unsigned integer,"
            " got 1.5: a real is no integer")  # fmt: skip
        self.rejected(
            "initiate and confirm set_state_bits of CpduN with arguments state := -1,"
            " mask := 1 end with;", PlutoTypeError,
            "activity set_state_bits of CpduN: argument state takes an unsigned integer,"
            " got -1: it is negative")  # fmt: skip
        self.rejected(
            'initiate and confirm label of CpduN with arguments text := 1, armed := TRUE,'
            " anything := 0 end with;", PlutoTypeError,
            "activity label of CpduN: argument text takes a string, got 1: types integer and"
            " string differ")  # fmt: skip
        self.rejected(
            "initiate and confirm label of CpduN with arguments text := \"a\", armed := 1,"
            " anything := 0 end with;", PlutoTypeError,
            "activity label of CpduN: argument armed takes a Boolean, got 1: types integer and"
            " Boolean differ")  # fmt: skip

    def test_wrong_unit(self):
        self.rejected(
            "initiate and confirm pulse of CpduN with arguments line := 1, width := 2 m"
            " end with;", PlutoTypeError,
            "activity pulse of CpduN: argument width takes a real in s, got 2 m: units m and"
            " s differ")  # fmt: skip
        self.rejected(
            "initiate and confirm set_state_bits of CpduN with arguments state := 1 V,"
            " mask := 1 end with;", PlutoTypeError,
            "activity set_state_bits of CpduN: argument state takes an unsigned integer, got"
            " 1 V: units V and none differ")  # fmt: skip

    def test_operation_request_statement_is_checked_too(self):
        self.rejected("set_state_bits of CpduN with state := 1 end with;", PlutoTypeError,
                      "activity set_state_bits of CpduN needs argument mask (takes: state,"
                      " mask)")  # fmt: skip

    def test_every_error_is_reported(self):
        s, _ = system()
        with self.assertRaises(PlutoTypeError) as c:
            load(procedure("initiate and confirm pulse of CpduN with arguments line := 1.5,"
                           " width := 2 V end with;"), s)  # fmt: skip
        self.assertEqual(len(c.exception.errors), 2)


class TestSimulated(unittest.TestCase):
    def test_system_file_declares_arguments(self):
        spec = {
            "activities": {
                "heat of Heater": {
                    "duration_s": 1,
                    "arguments": [{"name": "power", "type": "real", "unit": "W"},
                                  {"name": "time", "type": "relative time"}],
                }
            }
        }  # fmt: skip
        sim = SimulatedSystem(spec)
        self.assertEqual(
            sim.signature("heat of Heater"), [("power", "r", "W"), ("time", "rt", None)]
        )
        prog = load(procedure("initiate and confirm heat of Heater with arguments"
                              " power := 2 kW, time := 5 min end with;"), sim)  # fmt: skip
        p = Procedure(prog, sim)
        p.start(0)
        run_virtual(p, sim)
        self.assertEqual(p.outcome, "confirmed")
        with self.assertRaises(PlutoTypeError) as c:
            load(procedure("initiate heat of Heater with arguments power := 2 kW, time := 5"
                           " end with;"), sim)  # fmt: skip
        self.assertEqual(c.exception.msg, "activity heat of Heater: argument time takes a"
                         " relative time, got 5: it is no relative time")  # fmt: skip

    def test_undeclared_activity_takes_any_arguments(self):
        sim = SimulatedSystem({"activities": {"heat of Heater": {}}})
        self.assertIsNone(sim.signature("heat of Heater"))
        load(procedure("initiate heat of Heater with arguments 1, x := 2 end with;"), sim)


if __name__ == "__main__":
    unittest.main()
