"""The fuzz engine: a deterministic generator, byte mutations and a run loop (MicroPython subset).

A target is a decoder or entry point with valid seed inputs, an optional structure-aware
generator and the errors it declares. ``run`` feeds it mutated seeds and generated inputs and
keeps every exception that is not declared (an input that raises ``MemoryError`` or
``RecursionError`` is a finding like any other). The same code runs on CPython and on the
MicroPython unix port, so the same seeds give the same inputs on both.
"""

import time

try:
    _ticks = time.ticks_ms  # MicroPython

    def _elapsed(t0):
        return time.ticks_diff(time.ticks_ms(), t0) / 1000.0
except AttributeError:
    _ticks = time.monotonic

    def _elapsed(t0):
        return time.monotonic() - t0


class Rng:
    """xorshift32: small, fast and identical on every interpreter."""

    def __init__(self, seed):
        self.s = (seed * 2654435761 + 0x9E3779B9) & 0xFFFFFFFF or 1

    def next(self):
        x = self.s
        x ^= (x << 13) & 0xFFFFFFFF
        x ^= x >> 17
        x ^= (x << 5) & 0xFFFFFFFF
        self.s = x
        return x

    def below(self, n):
        return self.next() % n if n > 0 else 0

    def pick(self, seq):
        return seq[self.next() % len(seq)]

    def bytes(self, n):
        return bytes([self.next() & 0xFF for _ in range(n)])

    def chance(self, percent):
        return self.next() % 100 < percent


_INTERESTING = (0, 1, 0x7F, 0x80, 0xFF, 0xFE, 0x40, 0x10, 0x20)
_WIDE = (0, 1, 0x7FFF, 0x8000, 0xFFFF, 0x7FFFFFFF, 0x80000000, 0xFFFFFFFF, 0xFFFFFFFE)


def mutate(rng, data, others=()):
    """``data`` with one to four random edits: bit flips, interesting values, inserted,
    deleted and repeated runs, truncation, and splices with another seed. (Only edits that
    keep the length go through a bytearray: MicroPython's cannot grow or shrink a slice.)"""
    b = bytes(data)
    for _ in range(1 + rng.below(4)):
        op = rng.below(11)
        n = len(b)
        if op <= 2 and n:
            m = bytearray(b)
            i = rng.below(n)
            if op == 0:
                m[i] ^= 1 << rng.below(8)
            elif op == 1:
                m[i] = rng.pick(_INTERESTING)
            else:
                m[i] = rng.next() & 0xFF
            b = bytes(m)
        elif op == 3:
            i = rng.below(n + 1)
            b = b[:i] + rng.bytes(1 + rng.below(8)) + b[i:]
        elif op == 4 and n:
            i = rng.below(n)
            b = b[:i] + b[i + 1 + rng.below(8) :]
        elif op == 5 and n:
            i = rng.below(n)
            j = min(n, i + 1 + rng.below(16))
            b = b[:j] + b[i:j] * (1 + rng.below(4)) + b[j:]
        elif op == 6 and n:
            b = b[: rng.below(n)]
        elif op == 7 and n >= 2:
            i = rng.below(n - 1)
            v = rng.pick(_WIDE) & 0xFFFF
            b = b[:i] + bytes((v >> 8, v & 0xFF)) + b[i + 2 :]
        elif op == 8 and n >= 4:
            i = rng.below(n - 3)
            v = rng.pick(_WIDE)
            w = bytes(((v >> 24) & 0xFF, (v >> 16) & 0xFF, (v >> 8) & 0xFF, v & 0xFF))
            b = b[:i] + w + b[i + 4 :]
        elif op == 9 and others:
            o = rng.pick(others)
            b = b[: rng.below(n + 1)] + o[rng.below(len(o) + 1) :]
        elif op == 10:
            b = b + rng.bytes(rng.below(32))
    return b


class Target:
    """A decoder under fuzz: ``call(data)`` may raise only ``declared`` (a tuple)."""

    def __init__(self, name, call, seeds, declared=(), generate=None, reset=None, text=False):
        self.name = name
        self.call = call
        self.seeds = [s.encode() if isinstance(s, str) else s for s in seeds]
        self.declared = declared
        self.generate = generate  # optional: generate(rng) -> a structure-aware input
        self.reset = reset  # optional: called every 200 inputs (stateful entry points)
        self.text = text  # inputs are given to ``call`` as str (UTF-8, bad octets replaced)


class Result:
    def __init__(self, name):
        self.name = name
        self.tried = 0
        self.declared = 0  # inputs refused with a declared error
        self.undeclared = []  # (input, "ExceptionName: text"), the first ten kept
        self.undeclared_count = 0
        self.seconds = 0.0


def as_text(data):
    try:
        return data.decode()
    except UnicodeError:
        ascii_only = bytearray(data)
        for i in range(len(ascii_only)):
            if ascii_only[i] > 127:
                ascii_only[i] = 63  # "?"
        return ascii_only.decode()


def run(target, count=None, seconds=None, seed=1):
    """Fuzz ``target`` with ``count`` inputs or for ``seconds`` (whichever comes first)."""
    rng = Rng(seed)
    res = Result(target.name)
    seeds = target.seeds
    t0 = _ticks()
    i = 0
    while True:
        if count is not None and i >= count:
            break
        if seconds is not None and (i & 31) == 0 and _elapsed(t0) >= seconds:
            break
        if target.reset is not None and i % 200 == 0:
            target.reset()
        if i < len(seeds):
            data = seeds[i]
        elif target.generate is not None and rng.chance(30):
            data = target.generate(rng)
            if rng.chance(50):
                data = mutate(rng, data, seeds)
        else:
            data = mutate(rng, rng.pick(seeds), seeds)
        i += 1
        arg = as_text(data) if target.text else data
        try:
            target.call(arg)
        except target.declared:
            res.declared += 1
        except Exception as e:  # noqa: BLE001 - the point: anything else is a finding
            res.undeclared_count += 1
            if len(res.undeclared) < 10:
                res.undeclared.append((data, "%s: %s" % (type(e).__name__, e)))
    res.tried = i
    res.seconds = _elapsed(t0)
    return res


def line(res):
    return "%-22s %9d inputs  %6d refused  undeclared exceptions: %d  %.1f s" % (
        res.name,
        res.tried,
        res.declared,
        res.undeclared_count,
        res.seconds,
    )
