"""Run core unittest files on MicroPython (which ships no unittest): the unix port through
run.py, a board through ``import obsw_run_tests; obsw_run_tests.main([...])``.

main(files, skips, threshold, collect): prints a line per failure and 'N passed, N failed[, N
skipped]'; ``skips`` maps a file name or 'file::Class::test' to the reason it cannot run here
(counted as skipped); ``threshold`` (a board's) makes the GC collect after that many bytes
allocated rather than only when the heap is exhausted, which keeps a small heap from fragmenting
(``gc.threshold``); ``collect`` (a board's default) starts each test on a collected heap. The
unix port's large heap needs neither: there a collection before each of 1,600 tests marks every
module loaded so far and took two thirds of the run.
"""

import gc
import sys
import unittest


def _split(path):
    i = path.rfind("/")
    return (path[:i] if i >= 0 else "."), path[i + 1 :]


def _cases(module):
    for name in sorted(dir(module)):
        obj = getattr(module, name)
        if (
            isinstance(obj, type)
            and issubclass(obj, unittest.TestCase)
            and obj is not unittest.TestCase
        ):
            yield name, obj


def _skip(skips, filename, label):
    for key in (filename, label[label.find(filename) :]):
        if key in skips:
            return skips[key]
    return None


def run_file(path, counts, verbose, skips=None, collect=True):
    folder, filename = _split(path)
    skips = skips or {}
    reason = _skip(skips, filename, filename)
    if reason is not None:
        counts[2] += 1
        print("skip %s: %s" % (filename, reason))
        return
    modname = filename[:-3] if filename.endswith(".py") else filename
    if folder not in sys.path:
        sys.path.insert(0, folder)
    try:
        module = __import__(modname)
    except Exception as e:
        counts[1] += 1
        print("FAIL import %s" % path)
        sys.print_exception(e)
        return
    case = None
    for cname, cls in _cases(module):
        for tname in sorted(dir(cls)):
            if not tname.startswith("test"):
                continue
            case = None
            if collect:
                gc.collect()  # each test on a collected heap: what one left is not the next's
            label = "%s::%s::%s" % (path, cname, tname)
            reason = _skip(skips, filename, label)
            if reason is not None:
                counts[2] += 1
                print("skip %s: %s" % (label, reason))
                continue
            try:
                case = cls()
            except Exception as e:
                counts[1] += 1
                print("FAIL %s (constructor)" % label)
                sys.print_exception(e)
                continue
            try:
                case.setUp()
                try:
                    getattr(case, tname)()
                finally:
                    case.tearDown()
            except unittest.SkipTest as e:
                counts[2] += 1
                if verbose:
                    print("skip %s: %s" % (label, e))
            except Exception as e:
                counts[1] += 1
                print("FAIL %s" % label)
                sys.print_exception(e)
            else:
                counts[0] += 1
                if verbose:
                    print("ok   %s" % label)


def main(argv, skips=None, threshold=None, collect=True):
    verbose = "-v" in argv
    if threshold:
        gc.collect()
        gc.threshold(threshold)
    files = [a for a in argv if not a.startswith("-")]
    counts = [0, 0, 0]
    for path in files:
        run_file(path, counts, verbose, skips, collect)
    line = "%d passed, %d failed" % (counts[0], counts[1])
    if counts[2]:
        line += ", %d skipped" % counts[2]
    print(line)
    return 1 if counts[1] or not counts[0] else 0
