"""PLUTO constructs of the ECSS-E-ST-70-32C Annex A grammar added to the interpreter (save
context, status properties), and a procedure written by hand from the grammar that loads and
runs (the productions themselves are generated and counted by tests/host/test_pluto_annex_a.py;
docs/pluto.md shows that run)."""

import json
import unittest

from obsw.pluto.checker import PlutoTypeError
from obsw.pluto.dryrun import dry_run
from obsw.pluto.interp import load
from obsw.pluto.lexer import PlutoSyntaxError
from obsw.pluto.parser import parse
from obsw.pluto.system import SimulatedSystem

DATA = "tests/data/pluto/"


def read(name):
    with open(DATA + name) as f:
        return f.read()


def step(main, decl=""):
    return (
        "procedure\ninitiate and confirm step S\n%s\nmain\n%s\nend main\nend step;\nend procedure"
        % ("declare %s end declare" % decl if decl else "", main)
    )


SPEC = {
    "clock_start": "2025-01-01T00:00:00Z",
    "parameters": {
        "voltage of EPS": {"timeline": [[0, {"value": 7, "unit": "V"}], [5, 6.5]]},
        "mode of OBC": {"timeline": [[0, "SAFE"], [5, "NOMINAL"]]},
    },
    "activities": {"heat of Heater": {"duration_s": 5}},
}


class TestWrittenFromTheGrammar(unittest.TestCase):
    def test_every_production_loads_and_runs(self):
        spec = json.loads(read("annex_a.system.json"))
        t = dry_run(read("annex_a.pluto"), spec)
        self.assertEqual((t["error"], t.get("runtime_error")), (None, None))
        self.assertEqual(t["status"], "confirmed")
        self.assertEqual(t["log"][1:7], ["armed, CONF in NOMINAL", "zero", "1", "4", "7",
                                         "executing"])  # fmt: skip
        self.assertEqual(t["log"][7], "confirmed, gain TRUE, 4, 32")
        self.assertEqual(t["step_status"], {"Configure": "confirmed", "Second": "confirmed"})
        calls = [c["activity"] for c in t["activity_calls"]]
        self.assertEqual(calls[:3], ["set limit of EPS", "heat of Heater",
                                     "set_state_bits of CpduN"])  # fmt: skip
        self.assertEqual(t["activity_calls"][0]["arguments"],
                         {"limit": {"value": 3.4, "unit": "V"}, "mode": 2})  # fmt: skip


class TestSaveContext(unittest.TestCase):
    def test_snapshot_keeps_its_values(self):
        t = dry_run(
            step("save context refer to voltage of EPS by v0, refer to mode of OBC by m0"
                 " end context; wait for 10 s; log v0, \" \", m0, \" \", voltage of EPS, \" \","
                 " mode of OBC; log value of v0 > 6.8 V;"), SPEC)  # fmt: skip
        self.assertEqual(t["log"], ["7 V SAFE 6.5 V NOMINAL", "TRUE"])

    def test_end_context_is_optional(self):
        t = dry_run(step("save context refer to mode of OBC by m; log m;"), SPEC)
        self.assertEqual(t["log"], ["SAFE"])

    def test_saved_values_are_typed_and_read_only(self):
        sim = SimulatedSystem(SPEC)
        with self.assertRaises(PlutoTypeError) as c:
            load(step("save context refer to mode of OBC by m end context; log m > 3 V;"), sim)
        self.assertEqual(c.exception.msg, "cannot compare m (string) with 3 V: types string and"
                         " integer with units differ")  # fmt: skip
        with self.assertRaises(PlutoTypeError) as c:
            load(step('save context refer to mode of OBC by m; m := "x";'), sim)
        self.assertEqual(c.exception.msg, "m holds a saved context value, it cannot be assigned")
        with self.assertRaises(PlutoTypeError):
            load(step("save context refer to mode of OBC by m, refer to mode of OBC by m;"), sim)

    def test_saved_values_are_fresh_in_each_activation(self):
        prog = load(step("save context refer to mode of OBC by m; log m;"), SimulatedSystem(SPEC))
        self.assertEqual(len(list(prog.def_vars.values())[0]), 1)

    def test_syntax(self):
        for bad in ("save context refer mode of OBC by m;", "save context refer to mode of OBC;",
                    "save context refer to mode of OBC by m, x by y;"):  # fmt: skip
            with self.assertRaises(PlutoSyntaxError):
                parse(step(bad))
        with self.assertRaises(PlutoSyntaxError) as c:
            parse("procedure main save context refer to a of B by x; end main end procedure")
        self.assertIn("only initiate", c.exception.msg)


class TestStatusProperties(unittest.TestCase):
    def test_activity_and_step_statuses(self):
        src = (
            "procedure main initiate and confirm step A main initiate heat of Heater refer by H;"
            ' log execution status of H, "/", confirmation status of H; wait for 6 s;'
            ' log execution status of H, "/", confirmation status of H; end main end step;'
            ' initiate and confirm step B main log confirmation status of A, "/",'
            ' execution status of A; if confirmation status of A = "confirmed" then log "ok";'
            " end if; end main end step; end main end procedure"
        )
        t = dry_run(src, SPEC)
        self.assertEqual(t["log"], ["executing/not available", "completed/confirmed",
                                    "confirmed/completed", "ok"])  # fmt: skip

    def test_before_initiation(self):
        t = dry_run(step("log execution status of H, confirmation status of H;"
                         " initiate heat of Heater refer by H;"), SPEC)  # fmt: skip
        self.assertEqual(t["error"]["kind"], "unknown_reference")


if __name__ == "__main__":
    unittest.main()
