"""Run the fuzzers and print one line per decoder (MicroPython subset: runs on both interpreters).

    python tests/fuzz/run.py --seconds 40            # bounded: the time shared by all targets
    python tests/fuzz/run.py --inputs 1000000        # long: a million inputs per target
    python tests/fuzz/run.py --inputs 5000 --only cfdp-entity --seed 3
    micropython tests/fuzz/run.py --inputs 300       # the same seeds on the unix port

Exits non-zero if any target raised an exception it does not declare (the first inputs that
did are printed in hex so they can be replayed). The closing line is ``N passed, N failed``
(one per target) for ``tools/test``.
"""

import sys

_here = __file__.rsplit("/", 1)[0] if "/" in __file__ else "."
for _p in (_here, _here + "/../core"):
    if _p not in sys.path:
        sys.path.insert(0, _p)

import fuzzcore  # noqa: E402


def _args(argv):
    opts = {"seconds": None, "inputs": None, "only": None, "seed": 1, "host": True}
    i = 0
    while i < len(argv):
        a = argv[i]
        if a == "--core-only":
            opts["host"] = False
            i += 1
            continue
        if a not in ("--seconds", "--inputs", "--only", "--seed") or i + 1 >= len(argv):
            print(__doc__)
            raise SystemExit(2)
        v = argv[i + 1]
        key = a[2:]
        opts[key] = v if key == "only" else float(v) if key == "seconds" else int(v)
        i += 2
    return opts


def all_targets(host):
    import core_targets

    out = core_targets.targets()
    if host and sys.implementation.name == "cpython":
        import host_targets

        out += host_targets.targets()
    return out


def main(argv):
    opts = _args(argv)
    targets = all_targets(opts["host"])
    if opts["only"]:
        names = opts["only"].split(",")
        targets = [t for t in targets if t.name in names]
    per = None
    if opts["seconds"] is not None:
        per = opts["seconds"] / max(1, len(targets))
    count = opts["inputs"]
    if count is None and per is None:
        count = 1000
    passed = failed = total = 0
    seconds = 0.0
    print("fuzz on %s, seed %d" % (sys.implementation.name, opts["seed"]))
    for t in targets:
        res = fuzzcore.run(t, count=count, seconds=per, seed=opts["seed"])
        print(fuzzcore.line(res))
        total += res.tried
        seconds += res.seconds
        if res.undeclared_count:
            failed += 1
            for data, err in res.undeclared[:3]:
                print("    %s <- %s" % (err[:200], data[:120].hex()))
        else:
            passed += 1
    print("%d inputs in %.1f s, undeclared exceptions in %d targets" % (total, seconds, failed))
    print("%d passed, %d failed" % (passed, failed))
    return failed


if __name__ == "__main__":
    sys.exit(1 if main(sys.argv[1:]) else 0)
