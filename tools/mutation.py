#!/usr/bin/env python3
"""Mutation testing of the safety-critical core with cosmic-ray (PyPI): small realistic faults
put into a module one at a time, the module's tests run against each; a mutant the tests do not
notice (it survives) marks a behaviour nothing pins.

    python tools/mutation.py [MODULE...] [--sample N] [--seed S] [--jobs J] [--write] [--json]
    python tools/mutation.py --results FILE [--sample N] [--write]
    python tools/mutation.py [MODULE...] --draw N [--seed S]

MODULE is a name of TARGETS (default: all). The mutants are those a programmer makes: a
comparison turned into its neighbour (< and <=, == and !=, in and not in), a constant off by
one, + and - swapped, a condition negated, True and False swapped, and and or swapped, a loop
that never runs, a break that continues, an except clause that catches something else. Each
module is mutated in a copy of the tree of its own (cosmic-ray writes the mutant into the file),
its tests run on CPython with pytest under OBSW_PURE=1 (the Python paths the board runs, not
the C codec that takes over some of them on CPython); a mutant that makes them fail or hang is
killed.

`--sample N` takes N mutants of each module, chosen by `--seed`. `--draw N` (the `mutation`
stage of tools/test) draws N mutants across the modules, a module at a time in an order the seed
gives (printed; a fresh one unless `--seed` is given), and runs each against its module's
tests: its line says killed, equivalent (listed in EQUIVALENT: not run) or survived, and
`N passed, N failed` counts a survivor as a failure. The whole run (every mutant of every
module: hours on two cores) is a job run by hand, `--write` then writes docs/mutation.md.
Survivors that cannot be killed (the mutant does what the original does) are listed in
EQUIVALENT with the reason. Without `--draw` the last line is `N passed, N failed` of the
modules: a module passes with at least GOAL of its other mutants killed and every
survivor explained. `--json` prints the results; `--results FILE` reads them back from such a
run's output instead of running (to write the page again once survivors are explained).
"""

import argparse
import concurrent.futures
import glob
import json
import os
import random
import shutil
import sqlite3
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.realpath(__file__)))
GOAL = 0.90  # of the mutants of each module killed
TIMEOUT = 60.0  # seconds a mutant's tests may take (a hang kills it)

# module -> the test files (patterns in tests/core) that pin it; they also run on the unix port
TARGETS = {
    "pus/packets.py": [
        "test_pus_packets.py",
        "test_pus_app.py",
        "test_errors.py",
        "test_pus_boundaries.py",
    ],
    "pus/tc.py": [
        "test_pus_packets.py",
        "test_pus_app.py",
        "test_pus_random_requests.py",
        "test_pus_boundaries.py",
    ],
    "frames/farm.py": ["test_frames_farm*.py", "test_frames_boundaries.py", "test_frames_cop*.py"],
    "frames/fop.py": ["test_frames_fop*.py", "test_frames_boundaries.py", "test_frames_cop*.py"],
    "frames/sdls.py": ["test_frames_sdls*.py", "test_frames_boundaries.py"],
    "frames/cltu.py": ["test_frames_cltu*.py", "test_frames_boundaries.py"],
    "frames/rs.py": ["test_frames_rs*.py", "test_frames_coding*.py"],
    "cfdp/receiver.py": ["test_cfdp_*.py"],
    "cfdp/sender.py": ["test_cfdp_*.py"],
    "pluto/evaluate.py": ["test_pluto_*.py"],
    "reconfig/recovery.py": ["test_reconfig_*.py"],
    "update/package.py": ["test_update_*.py"],
}

# the kinds of mutant kept (cosmic-ray operator names, without "core/")
OPERATORS = {
    "ReplaceComparisonOperator_Lt_LtE", "ReplaceComparisonOperator_LtE_Lt",
    "ReplaceComparisonOperator_Gt_GtE", "ReplaceComparisonOperator_GtE_Gt",
    "ReplaceComparisonOperator_Eq_NotEq", "ReplaceComparisonOperator_NotEq_Eq",
    "ReplaceComparisonOperator_In_NotIn", "ReplaceComparisonOperator_NotIn_In",
    "ReplaceComparisonOperator_Is_IsNot", "ReplaceComparisonOperator_IsNot_Is",
    "NumberReplacer", "ReplaceBinaryOperator_Add_Sub", "ReplaceBinaryOperator_Sub_Add",
    "AddNot", "ReplaceTrueWithFalse", "ReplaceFalseWithTrue", "ReplaceAndWithOr",
    "ReplaceOrWithAnd", "ZeroIterationForLoop", "ReplaceBreakWithContinue", "ExceptionReplacer",
}  # fmt: skip

# (module, line, operator) -> why the mutant cannot be told from the original (lines move with
# the code: tests/host/test_mutation_tool.py checks that each entry names a mutant there is)
EQUIVALENT = {
    ("frames/rs.py", 61, "AddNot"): "the flag only picks bytes.translate or a loop over the same "
    "table: the same octets either way",
    ("frames/rs.py", 35, "ReplaceBinaryOperator_Add_Sub"): "exp holds 2N entries: exp[i - N] "
    "is exp[i + N] by negative indexing",
    ("frames/rs.py", 146, "AddNot"): "the flag only picks slicing or a loop over the same "
    "indexes to split a block into its interleaved words: the same octets either way",
    ("frames/rs.py", 155, "AddNot"): "the flag only picks slice assignment or a loop over the "
    "same indexes to join the words again: the same octets either way",
    ("frames/rs.py", 144, "NumberReplacer"): "interleaving depth 1 then takes the slicing path, "
    "whose one slice block[0::1] is the same octets",
    ("frames/rs.py", 248, "NumberReplacer"): "Berlekamp-Massey keeps the locator's degree at or "
    "below the step, so lam[step + 1] is 0 and the extra term adds nothing",
    ("frames/rs.py", 269, "NumberReplacer"): "a degree-0 locator cannot occur: a zero remainder "
    "returns before, and a nonzero one (degree < 2E) cannot vanish at all 2E roots",
    ("frames/rs.py", 272, "NumberReplacer"): "lam[deg + 1] is 0 (deg is the highest nonzero "
    "coefficient) and the search reads only the first deg + 1 logs",
    ("cfdp/receiver.py", 48, "NumberReplacer"): "called only with more gaps than max_gaps (at "
    "least 2), so the loop always runs and sets best",
    ("cfdp/receiver.py", 151, "ReplaceComparisonOperator_GtE_Gt"): "upto is only ever the "
    "progress, and every gap ends at or below it: no gap starts at it",
    ("cfdp/sender.py", 268, "ReplaceTrueWithFalse"): "Transaction.save ignores force: every "
    "save writes the state",
    ("reconfig/recovery.py", 172, "ReplaceBinaryOperator_Add_Sub"): "while the OBC lines read 0 "
    "every poll returns None whatever the deadline, and the first change of the lines sets it "
    "afresh",
    ("frames/fop.py", 401, "NumberReplacer"): "Look for Directive runs only in state S5 "
    "(Initializing with BC frame), where the sent queue holds the one BC frame: first is last",
    ("pus/tc.py", 74, "ReplaceComparisonOperator_IsNot_Is"): "the C codec's path (not taken under "
    "OBSW_PURE); where it runs, the Python code after it packs the same octets",
    ("pus/tc.py", 153, "ReplaceComparisonOperator_IsNot_Is"): "the C codec's path (not taken "
    "under OBSW_PURE); where it runs, the Python code after it decodes the same packet",
    ("pus/tc.py", 134, "NumberReplacer"): "< 1 sends all-zero fields to _check, which passes "
    "them; < -1 lets -1 through _lax: CPython's struct.pack refuses it and pack names the field "
    "as _check does; on the unix port (struct.pack truncates) test_pus_boundaries.py kills it",
    ("pus/tc.py", 135, "NumberReplacer"): ">> 7 sends 128..255 to _check, which passes them; "
    ">> 9 lets 256 through _lax: CPython's struct.pack refuses it and pack names the field as "
    "_check does; on the unix port (struct.pack truncates) test_pus_boundaries.py kills it",
    ("pus/tc.py", 135, "ReplaceOrWithAnd"): "lets a service or subtype of 256 through _lax: "
    "CPython's struct.pack refuses it and pack names the field as _check does; on the unix port "
    "(struct.pack truncates) test_pus_boundaries.py kills it",
    ("pus/tc.py", 165, "ReplaceOrWithAnd"): "only picks the fast path or the careful one: with "
    "a PEC no packet takes the fast path, without one only those whose CRC comes to 0, and the "
    "careful path checks and decodes the rest alike",
    ("pus/tc.py", 134, "ReplaceComparisonOperator_Lt_LtE"): "only decides whether _check runs: "
    "with all four fields zero it passes them, so running it too changes nothing",
}


def copy_tree(dest):
    """The files the tests need, copied (cosmic-ray mutates files in place)."""
    files = subprocess.run(["git", "-C", ROOT, "ls-files", "-z", "micropython", "tests/core",
                            "tests/conftest.py", "pyproject.toml"],
                           capture_output=True, check=True).stdout.split(b"\0")  # fmt: skip
    for f in files:
        if f:
            src = os.path.join(ROOT, f.decode())
            dst = os.path.join(dest, f.decode())
            os.makedirs(os.path.dirname(dst), exist_ok=True)
            shutil.copy2(src, dst)


def cosmic(args, cwd):
    tool = os.path.join(os.path.dirname(sys.executable), "cosmic-ray")
    env = dict(os.environ, OBSW_PURE="1")  # the mutated Python code runs, never the C codec
    return subprocess.run([tool] + args, cwd=cwd, capture_output=True, text=True, env=env)


def run_module(module, sample, seed):
    """Mutate ``module``: {'module', 'total', 'killed', 'survived': [...], 'seconds'}."""
    t0 = time.monotonic()
    with tempfile.TemporaryDirectory(prefix="obsw-mutation-") as work:
        copy_tree(work)
        found = set()
        for pattern in TARGETS[module]:
            found.update(glob.glob(os.path.join(work, "tests", "core", pattern)))
        tests = " ".join(os.path.relpath(t, work) for t in sorted(found))
        config = os.path.join(work, "cr.toml")
        with open(config, "w") as f:
            f.write(
                '[cosmic-ray]\nmodule-path = "micropython/obsw/%s"\ntimeout = %s\n'
                "excluded-modules = []\n"
                'test-command = "%s -m pytest -x -q -p no:cacheprovider %s"\n'
                '[cosmic-ray.distributor]\nname = "local"\n'
                % (module, TIMEOUT, sys.executable, tests)
            )
        session = os.path.join(work, "session.sqlite")
        r = cosmic(["init", config, session], work)
        if r.returncode:
            raise RuntimeError("cosmic-ray init: %s" % r.stderr.strip()[-500:])
        kept = choose(session, sample, seed)
        r = cosmic(["exec", config, session], work)
        if r.returncode:
            raise RuntimeError("cosmic-ray exec: %s" % r.stderr.strip()[-500:])
        return results(session, module, kept, time.monotonic() - t0)


def mutants(work, modules):
    """Every kept mutant (OPERATORS) of ``modules`` in the tree copied to ``work``: a list of
    (module, line, operator, occurrence), in the order of the files."""
    config = os.path.join(work, "all.toml")
    paths = ", ".join('"micropython/obsw/%s"' % m for m in modules)
    with open(config, "w") as f:
        f.write('[cosmic-ray]\nmodule-path = [%s]\ntimeout = %s\nexcluded-modules = []\n'
                'test-command = "true"\n[cosmic-ray.distributor]\nname = "local"\n'
                % (paths, TIMEOUT))  # fmt: skip
    session = os.path.join(work, "all.sqlite")
    r = cosmic(["init", config, session], work)
    if r.returncode:
        raise RuntimeError("cosmic-ray init: %s" % r.stderr.strip()[-500:])
    db = sqlite3.connect(session)
    rows = db.execute(
        "select module_path, start_pos_row, start_pos_col, operator_name, occurrence "
        "from mutation_specs"
    ).fetchall()
    db.close()
    found = []
    for path, row, col, op, occurrence in sorted(rows):
        op = op.split("/", 1)[-1]
        if op in OPERATORS:
            module = os.path.relpath(os.path.join(work, path), os.path.join(work, "micropython",
                                                                           "obsw"))  # fmt: skip
            found.append((module, row, col, op, occurrence))
    return [(m, row, op, occ) for m, row, _, op, occ in found]


def draw(modules, n, seed):
    """``n`` mutants drawn across ``modules`` with ``seed``, each run against its module's
    tests: a module at a time in a seeded order, a mutant of it at random. Prints a line for
    each; True for each that the tests killed (or that EQUIVALENT explains)."""
    rng = random.Random(seed)
    with tempfile.TemporaryDirectory(prefix="obsw-mutation-") as work:
        copy_tree(work)
        pool = {}
        for m, line, op, occ in mutants(work, modules):
            pool.setdefault(m, []).append((line, op, occ))
        order = [m for m in modules if pool.get(m)]
        rng.shuffle(order)
        chosen = []
        while len(chosen) < n and any(pool.get(m) for m in order):
            for m in order:
                if pool.get(m) and len(chosen) < n:
                    chosen.append((m,) + pool[m].pop(rng.randrange(len(pool[m]))))
        return [check(work, *c) for c in chosen]


def check(work, module, line, op, occurrence):
    """One mutant run against its module's tests in ``work``; printed; True if killed or
    equivalent."""
    why = EQUIVALENT.get((module, line, op))
    if why:
        print("ok   %-22s line %4d %-36s equivalent" % (module, line, op))
        return True
    path = os.path.join("micropython", "obsw", module)
    shutil.copy2(os.path.join(ROOT, path), os.path.join(work, path))  # the original again
    tests = set()
    for pattern in TARGETS[module]:
        tests.update(glob.glob(os.path.join(work, "tests", "core", pattern)))
    command = "%s -m pytest -x -q -p no:cacheprovider %s" % (
        sys.executable, " ".join(os.path.relpath(t, work) for t in sorted(tests)))  # fmt: skip
    tool = os.path.join(os.path.dirname(sys.executable), "cosmic-ray")
    env = dict(os.environ, OBSW_PURE="1")
    try:
        r = subprocess.run([tool, "mutate-and-test", path, "core/" + op, str(occurrence),
                            command], cwd=work, capture_output=True, text=True, env=env,
                           timeout=TIMEOUT)  # fmt: skip
        result = json.loads(r.stdout)
        outcome = (result.get("test_outcome") or "").lower()
        if (result.get("worker_outcome") or "").lower() != "normal":
            outcome = "could not run: %s" % result.get("worker_outcome")
    except subprocess.TimeoutExpired:
        outcome = "killed"  # the tests hung
    except ValueError:
        outcome = "could not run: %s" % (r.stderr.strip()[-300:] or r.stdout[-300:])
    ok = outcome in ("killed", "incompetent")  # incompetent: not valid Python, no mutant
    print("%-4s %-22s line %4d %-36s %s" % ("ok" if ok else "FAIL", module, line, op, outcome))
    return ok


def choose(session, sample, seed):
    """Keep the mutants of OPERATORS (a sample of ``sample`` of them); their count."""
    db = sqlite3.connect(session)
    rows = db.execute(
        "select job_id, operator_name, start_pos_row, start_pos_col, occurrence "
        "from mutation_specs"
    ).fetchall()
    # by place in the file, not by job id (a fresh random id each init): the same seed, the
    # same sample
    ordered = sorted((r[2], r[3], r[1], r[4], r[0]) for r in rows)
    keep = [r[-1] for r in ordered if r[2].split("/", 1)[-1] in OPERATORS]
    if sample:
        keep = random.Random(seed).sample(keep, min(sample, len(keep)))
    keep = set(keep)
    drop = [(r[0],) for r in rows if r[0] not in keep]
    db.executemany("delete from mutation_specs where job_id = ?", drop)
    db.executemany("delete from work_items where job_id = ?", drop)
    db.commit()
    db.close()
    return len(keep)


def results(session, module, total, seconds):
    db = sqlite3.connect(session)
    rows = db.execute(
        "select s.operator_name, s.start_pos_row, r.test_outcome, r.worker_outcome, r.diff "
        "from mutation_specs s join work_results r on s.job_id = r.job_id"
    ).fetchall()
    db.close()
    survived, killed, ran = [], 0, 0
    for op, line, test, worker, diff in rows:
        test, worker = (test or "").lower(), (worker or "").lower()  # enum names: "SURVIVED"
        if worker not in ("normal", "timeout"):  # the mutant could not be made or run
            raise RuntimeError("line %d %s: cosmic-ray %s" % (line, op, worker))
        if test == "incompetent":  # not valid Python: no mutant at all
            continue
        ran += 1
        if test == "survived" and worker == "normal":
            op = op.split("/", 1)[-1]
            why = EQUIVALENT.get((module, line, op))
            change = [d for d in (diff or "").splitlines() if d.startswith(("-", "+"))
                      and not d.startswith(("---", "+++"))]  # fmt: skip
            survived.append({"line": line, "operator": op, "change": change, "equivalent": why})
        else:  # the tests failed, or hung (a timeout)
            killed += 1
    return {"module": module, "total": total, "killed": killed, "ran": ran,
            "survived": sorted(survived, key=lambda s: s["line"]), "seconds": seconds}  # fmt: skip


def verdict(r):
    """(killed share of the mutants that differ from the original, goal met): a mutant listed
    in EQUIVALENT does what the original does, so no test can kill it and it is not counted."""
    unexplained = [s for s in r["survived"] if not s["equivalent"]]
    real = r["ran"] - (len(r["survived"]) - len(unexplained))
    rate = r["killed"] / real if real else 1.0
    return rate, rate >= GOAL and not unexplained


def page(results_, sample):
    out = [
        "# Mutation testing",
        "",
        "Written by `tools/mutation.py --write` (cosmic-ray); nothing on this page is typed by",
        "hand. Each module of the safety-critical core is mutated one realistic fault at a time",
        "(a comparison turned into its neighbour, a constant off by one, `+` and `-` swapped, a",
        "condition negated, `True` and `False` or `and` and `or` swapped, a loop that never runs,",
        "a `break` that continues, an `except` that catches something else) and its tests run",
        "against each mutant. Goal: at least %d %% of each module's mutants killed, every"
        % round(GOAL * 100),
        "survivor killed or explained as equivalent (it does what the original does: no test",
        "can tell them apart; the reason is given below, and `killed %` is of the others).",
        "",
        "Run: %s%s."
        % (
            time.strftime("%Y-%m-%d", time.gmtime()),
            ", a sample of %d mutants per module" % sample if sample else ", every mutant",
        ),  # fmt: skip
        "",
        "| module | mutants | killed | equivalent | survived | killed % | goal |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in results_:
        rate, ok = verdict(r)
        same = sum(1 for s in r["survived"] if s["equivalent"])
        out.append("| `%s` | %d | %d | %d | %d | %.1f | %s |" % (
            r["module"], r["ran"], r["killed"], same, len(r["survived"]) - same, 100 * rate,
            "met" if ok else "MISSED"))  # fmt: skip
    for r in results_:
        if not r["survived"]:
            continue
        out += ["", "## Survivors in `micropython/obsw/%s`" % r["module"], ""]
        for s in r["survived"]:
            change = "; ".join("`%s`" % c.strip() for c in s["change"][:2])
            why = " (equivalent: %s)" % s["equivalent"] if s["equivalent"] else ""
            out.append("- line %d, %s: %s%s" % (s["line"], s["operator"], change, why))
    return "\n".join(out) + "\n"


def tell(r):
    """Print a module's line (and its unexplained survivors); True if it met the goal."""
    rate, ok = verdict(r)
    print("%-4s %-22s %4d mutants, %4d killed, %3d survived (%5.1f %%) %6.0f s" % (
        "ok" if ok else "MISS", r["module"], r["ran"], r["killed"], len(r["survived"]),
        100 * rate, r["seconds"]))  # fmt: skip
    for s in r["survived"]:
        if not s["equivalent"]:
            change = " / ".join(c.strip() for c in s["change"])
            print("       line %d %s: %s" % (s["line"], s["operator"], change))
    return ok


def saved(path):
    """The results list a ``--json`` run printed (the one line of the file that is one)."""
    with open(path) as f:
        for line in f:
            if line.startswith("["):
                return json.loads(line)
    raise SystemExit("%s: no results (the output of a --json run)" % path)


def explained(r):
    """``r`` with each survivor's explanation as EQUIVALENT gives it now."""
    for s in r["survived"]:
        s["equivalent"] = EQUIVALENT.get((r["module"], s["line"], s["operator"]))
    return r


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("modules", nargs="*", metavar="MODULE", help="of: " + ", ".join(TARGETS))
    ap.add_argument("--sample", type=int, default=0, help="mutants per module (0: all)")
    ap.add_argument("--seed", type=int, help="of the sample or draw (default: 1 for --sample, "
                    "a fresh one, printed, for --draw)")  # fmt: skip
    ap.add_argument("--draw", type=int, metavar="N",
                    help="N mutants drawn across the modules, each run against its module's "
                    "tests: passed if killed or equivalent")  # fmt: skip
    ap.add_argument("--jobs", type=int, default=2, help="modules mutated at once")
    ap.add_argument("--write", action="store_true", help="write docs/mutation.md")
    ap.add_argument("--json", action="store_true", help="print the results as JSON")
    ap.add_argument("--results", metavar="FILE",
                    help="no run: the results a --json run printed to FILE, explained by "
                    "EQUIVALENT as it is now (give --sample as that run had it)")  # fmt: skip
    args = ap.parse_args(argv)
    unknown = [m for m in args.modules if m not in TARGETS]
    if unknown:
        ap.error("unknown module %s (of: %s)" % (", ".join(unknown), ", ".join(TARGETS)))
    if not os.path.exists(os.path.join(os.path.dirname(sys.executable), "cosmic-ray")):
        print("cosmic-ray not installed: pip install cosmic-ray (a dev dependency)")
        print("0 passed, 1 failed")
        return 1
    modules = args.modules or list(TARGETS)
    if args.draw:
        seed = args.seed if args.seed is not None else random.SystemRandom().randrange(10**6)
        print("%d mutants drawn from %d modules, seed %d (again: --draw %d --seed %d)"
              % (args.draw, len(modules), seed, args.draw, seed))  # fmt: skip
        try:
            oks = draw(modules, args.draw, seed)
        except RuntimeError as e:  # the modules could not be read for mutants
            print("FAIL %s" % e)
            oks = [False]
        print("%d passed, %d failed" % (sum(oks), len(oks) - sum(oks)))
        return 0 if all(oks) else 1
    if args.seed is None:
        args.seed = 1
    done, passed, failed = [], 0, 0
    if args.results:
        done = [explained(r) for r in saved(args.results) if r["module"] in modules]
        for r in done:
            ok = tell(r)
            passed, failed = passed + ok, failed + (not ok)
        modules = [m for m in modules if any(r["module"] == m for r in done)]
    else:
        with concurrent.futures.ThreadPoolExecutor(max(1, args.jobs)) as pool:
            futures = {pool.submit(run_module, m, args.sample, args.seed): m for m in modules}
            for fut in concurrent.futures.as_completed(futures):
                m = futures[fut]
                try:
                    r = fut.result()
                except Exception as e:  # a module that cannot be mutated: a failure, said once
                    failed += 1
                    print("FAIL %-22s %s" % (m, e))
                    continue
                done.append(r)
                ok = tell(r)
                passed, failed = passed + ok, failed + (not ok)
    done.sort(key=lambda r: modules.index(r["module"]))
    if args.write:
        with open(os.path.join(ROOT, "docs", "mutation.md"), "w") as f:
            f.write(page(done, args.sample))
    if args.json:
        print(json.dumps(done))
    print("%d passed, %d failed" % (passed, failed))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
