"""PLUTO benchmark: parse+check time of a 200-line procedure and statements executed per second.

The reference rows are plain Python doing the same work directly (the loop the procedure
describes, and tokenizing the text with str.split), to show the interpreter's overhead.

    tools/bench/pluto.py [--json] [--quick]
"""

import argparse
import json
import pathlib
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent.parent
sys.path.insert(0, str(ROOT / "micropython"))

from measure import median_of  # noqa: E402
from obsw.pluto.interp import Procedure, load  # noqa: E402
from obsw.pluto.system import SimulatedSystem  # noqa: E402


def procedure_200_lines():
    """A procedure of exactly 200 lines mixing the statement kinds an OBCP uses."""
    head = [
        "procedure",
        '  declare event Late described by "too slow" end declare',
        "  main",
        "    initiate and confirm step Work",
        "      declare",
        "        variable i of type signed integer,",
        "        variable v of type real with units V,",
        "        variable t of type relative time",
        "      end declare",
        "      main",
        "        i := 0;",
    ]
    tail = [
        "      end main",
        "      confirmation if i >= 0 end confirmation",
        "    end step;",
        '    inform user "done";',
        "  end main",
        "end procedure",
    ]
    body = []
    k = 0
    while len(head) + len(body) + len(tail) < 200:
        block = [
            "        v := %d.5 V + 250 mV * 2;" % k,
            "        if v > 3 V AND i < 1000 then i := i + 1; else i := i - 1; end if;",
            "        t := 1 min 30 s + %d s;" % k,
            '        in case i is = 1: log "one"; or is between 2 and 9: log i; end case;',
            "        while i < %d timeout 10 s raise event Late do i := i + 1; end while;"
            % (k * 3),
        ]
        body.extend(block[: 200 - len(head) - len(body) - len(tail)])
        k += 1
    lines = head + body + tail
    assert len(lines) == 200, len(lines)
    return "\n".join(lines) + "\n"


LOOP = """procedure
  initiate and confirm step Count
    declare variable i of type signed integer end declare
    main
      i := 0;
      while i < %d do
        i := i + 1;
      end while;
    end main
  end step;
end procedure
"""


def bench_parse(src):
    t0 = time.perf_counter()
    load(src)
    return time.perf_counter() - t0


def bench_parse_reference(src):
    t0 = time.perf_counter()
    src.replace(";", " ; ").replace("(", " ( ").split()
    return time.perf_counter() - t0


def bench_run(n):
    prog = load(LOOP % n)
    p = Procedure(prog, SimulatedSystem({}))
    p.start(0)
    t0 = time.perf_counter()
    p.run(0)
    dt = time.perf_counter() - t0
    assert p.outcome == "confirmed", p.error
    return p.statements / dt


def bench_run_reference(n):
    t0 = time.perf_counter()
    i = 0
    count = 0
    while i < n:
        i = i + 1
        count += 1
    return count / (time.perf_counter() - t0)


def main(argv=None):
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawTextHelpFormatter
    )
    ap.add_argument("--json", action="store_true", help="print one JSON object")
    ap.add_argument("--quick", action="store_true", help="smaller, under a minute")
    a = ap.parse_args(argv)
    runs, n = (5, 20000) if a.quick else (11, 200000)
    src = procedure_200_lines()
    parse_s = median_of(lambda: bench_parse(src), runs)
    ref_parse_s = median_of(lambda: bench_parse_reference(src), runs)
    sps = median_of(lambda: bench_run(n), runs)
    ref_sps = median_of(lambda: bench_run_reference(n), runs)
    rows = [
        {"case": "parse+check 200-line procedure", "impl": "obsw", "value": parse_s * 1000,
         "unit": "ms", "higher_is_better": False},
        {"case": "parse+check 200-line procedure", "impl": "reference",
         "value": ref_parse_s * 1000,
         "unit": "ms", "higher_is_better": False},
        {"case": "statements executed", "impl": "obsw", "value": sps, "unit": "statements/s",
         "higher_is_better": True},
        {"case": "statements executed", "impl": "reference", "value": ref_sps,
         "unit": "statements/s", "higher_is_better": True},
    ]  # fmt: skip
    if a.json:
        print(json.dumps({"bench": "pluto", "rows": rows}))
        return 0
    print("%-32s %14s %14s %8s  %s" % ("case", "obsw", "reference", "ratio", "unit"))
    for i in (0, 2):
        ours, ref = rows[i], rows[i + 1]
        ratio = ours["value"] / ref["value"]
        print("%-32s %14.4g %14.4g %8.3g  %s" % (
            ours["case"], ours["value"], ref["value"], ratio, ours["unit"]))  # fmt: skip
    print("(%d lines; loop of %d iterations; medians of %d runs)" % (200, n, runs))
    return 0


if __name__ == "__main__":
    sys.exit(main())
