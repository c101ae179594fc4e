"""The Annex A grammar of ECSS-E-ST-70-32C, as pluto-parser ships it (ISO EBNF, with Annex B's
engineering units), read into productions: a generator of procedures from it that counts what
it covered per production, and a reference parser (Lark, Earley) built from the same text.

Run as a script to rewrite the production table of docs/pluto.md from a grammar run
(``python tests/host/pluto_annex_a.py --write``; ``--check`` says whether it is current).
"""

import os
import random
import re
import sys
from importlib import resources

# The lexical productions: their parts are written together, without spaces, as one token.
# Identifier words, numbers, times, strings and a unit symbol with its prefix.
LEXICAL = {
    "Letter",
    "Digit",
    "Hexadecimal Digit",
    "Hexadecimal Symbol",
    "Year",
    "Month",
    "Day",
    "Day Of Month",
    "Hour",
    "Minute",
    "Second",
    "Absolute Time Constant",
    "Characters",
    "Days",
    "Hours",
    "Minutes",
    "Seconds",
    "Fraction Of Second",
    "Hexadecimal Constant",
    "Identifier First Word",
    "Identifier Subsequent Word",
    "String Constant",
    "Enumerated Constant",
    "Unit Simple Factor",
    "Unsigned Integer",
}
# Productions whose parts are written together except their engineering units, which follow
# after a space ("12.5e-3 V", "1d2h30min", "-1:02:03:04:005").
NUMERIC = {"Integer Constant", "Real Constant", "Relative Time Constant"}


def _replace(node, old, new):
    """``node`` with every reference to production ``old`` made one to ``new``."""
    k = node[0]
    if k == "ref":
        return ("ref", new) if node[1] == old else node
    if k in ("seq", "alt"):
        return (k, tuple(_replace(x, old, new) for x in node[1]))
    if k == "opt":
        return (k, _replace(node[1], old, new))
    if k == "rep":
        return (k, _replace(node[1], old, new), node[2])
    return node


def _no_step_activity(prods):
    """'initiate and confirm step X;' is a step statement: Annex A also reads it as an
    activity whose reference has the object type step, which no activity has."""
    types = prods["Object Type"]
    prods["Activity Object Type"] = ("alt", tuple(x for x in types[1] if x != ("lit", "step")))
    prods["Confirmed Activity Reference"] = _replace(prods["Object Reference"], "Object Type",
                                                     "Activity Object Type")  # fmt: skip
    prods["Confirmed Activity Call"] = _replace(prods["Activity Call"], "Activity Reference",
                                                "Confirmed Activity Reference")  # fmt: skip
    name = "Initiate And Confirm Activity Statement"
    prods[name] = _replace(prods[name], "Activity Call", "Confirmed Activity Call")


# Where this implementation reads Annex A in one way where the grammar allows two, as
# docs/pluto.md says: each a change of the productions, named after what it decides.
DISAMBIGUATIONS = (_no_step_activity,)


def _read(name):
    return resources.files("pluto_parser").joinpath("grammar", name).read_text()


_TOKEN = re.compile(
    r'\s*(?:("(?:\\.|[^"\\])*")|(\?[^?]*\?)|([A-Za-z][A-Za-z ]*[A-Za-z]|[A-Za-z])|(\d+)|(.))',
    re.S,
)


def _tokens(text):
    out = []
    for m in _TOKEN.finditer(text):
        lit, special, name, num, sym = m.groups()
        if lit is not None:
            out.append(("lit", lit[1:-1]))
        elif special is not None:
            out.append(("ref", special.strip("? ")))
        elif name is not None:
            out.append(("ref", name.strip()))
        elif num is not None:
            out.append(("num", int(num)))
        elif sym is not None and not sym.isspace():
            out.append(("sym", sym))
    return out


class _Reader:
    """ISO 14977 EBNF as Annex A writes it: ',' sequence, '|' choice, [ ] option,
    { } repetition, { }- one or more, ( ) group, n * x repetition n times."""

    def __init__(self, text):
        self.t = _tokens(text)
        self.i = 0

    def peek(self):
        return self.t[self.i] if self.i < len(self.t) else ("eof", None)

    def take(self, sym):
        if self.peek() == ("sym", sym):
            self.i += 1
            return True
        return False

    def productions(self):
        out = {}
        while self.peek()[0] != "eof":
            kind, name = self.peek()
            assert kind == "ref", self.peek()
            self.i += 1
            assert self.take("="), name
            out[name] = self.alt()
            assert self.take(";"), (name, self.peek())
        return out

    def alt(self):
        items = [self.seq()]
        while self.take("|"):
            items.append(self.seq())
        return items[0] if len(items) == 1 else ("alt", tuple(items))

    def seq(self):
        items = [self.item()]
        while self.take(","):
            items.append(self.item())
        return items[0] if len(items) == 1 else ("seq", tuple(items))

    def item(self):
        kind, v = self.peek()
        if kind == "num":
            self.i += 1
            assert self.take("*")
            x = self.item()
            return ("seq", (x,) * v)
        self.i += 1
        if kind in ("lit", "ref"):
            return (kind, v)
        if v == "(":
            x = self.alt()
            assert self.take(")")
            return x
        if v == "[":
            x = self.alt()
            assert self.take("]")
            return ("opt", x)
        if v == "{":
            x = self.alt()
            assert self.take("}")
            return ("rep", x, 1 if self.take("-") else 0)
        raise AssertionError("unexpected %r" % v)


def _unescape(node):
    k = node[0]
    if k == "lit":
        return ("lit", node[1].replace('\\"', '"').replace("\\\\", "\\"))
    if k in ("seq", "alt"):
        return (k, tuple(_unescape(x) for x in node[1]))
    if k == "opt":
        return (k, _unescape(node[1]))
    if k == "rep":
        return (k, _unescape(node[1]), node[2])
    return node


def productions():
    """Annex A's productions and Annex B's engineering units, by name."""
    text = _read("pluto.ebnf")
    # the transcription lost a ',' between two parts of the case statement
    typo = '":", {Step Statement, ";"}-\n'
    assert text.count(typo) == 1
    text = text.replace(typo, typo[:-1] + ",\n")
    prods = _Reader(text).productions()
    units = _read("engineering_units.ebnf").replace(
        "? Engineering Units ? =", "Engineering Units ="
    )
    units = units.replace("Unit Simple Factor  =", "Unit Simple Factor =")
    # Annex B's railroad diagram (B.2.g.7) has one simple factor where this text has two
    typo = "Unit Simple Factor (Unit Simple Factor ,"
    assert units.count(typo) == 1
    units = units.replace(typo, "(Unit Simple Factor ,")
    uprods = _Reader(units).productions()
    prods.update(uprods)
    # '"\\""' is the quote that opens and closes a string; inside a string (Characters) the
    # quote and the backslash are written as escapes, '\\"' and '\\\\'
    for n, node in prods.items():
        if n != "Characters":
            prods[n] = _unescape(node)
    for patch in DISAMBIGUATIONS:
        patch(prods)
    return prods


def choice_points(prods):
    """Every alternative and optional clause, as (production, path): what coverage counts."""
    out = []

    def walk(name, node, path):
        k = node[0]
        if k == "alt":
            for j, x in enumerate(node[1]):
                out.append((name, path + "|%d" % j))
                walk(name, x, path + "|%d" % j)
        elif k == "seq":
            for j, x in enumerate(node[1]):
                walk(name, x, path + ".%d" % j)
        elif k == "opt":
            out.append((name, path + "[+]"))
            out.append((name, path + "[-]"))
            walk(name, node[1], path + "[]")
        elif k == "rep":
            out.append((name, path + "{1}"))
            out.append((name, path + "{n}"))
            if node[2] == 0:
                out.append((name, path + "{0}"))
            walk(name, node[1], path + "{}")

    for name, node in prods.items():
        if name in NUMERIC:  # written by Generator.numeric, which counts these
            out.extend((name, c) for c in NUMERIC_POINTS[name])
        elif name not in LEXICAL or name == "Unit Simple Factor":
            walk(name, node, "")
    return out


NUMERIC_POINTS = {
    "Integer Constant": ("|0", "|1", "[+]", "[-]"),  # decimal or hexadecimal; units or none
    "Real Constant": ("[+]", "[-]", ".", "e"),  # units or none; a fraction; an exponent
    "Relative Time Constant": ("|0", "|1"),  # with units (1d2h) or with colons
}


# ---------------------------------------------------------------------------------------------
# generation

# Words of identifiers: none is a keyword of the grammar, a unit symbol, a function of Annex C
# or an object type, so that a sentence means one thing.
FIRST_WORDS = ("Heater", "EPS", "battery", "voltage", "Wheel", "pump", "Exposure", "gain", "x",
               "Camera", "Valve3", "torquer", "sun_sensor")  # fmt: skip
NEXT_WORDS = ("A", "mode", "1", "07", "limit", "Main", "x2")
STRINGS = ("hello", "battery low", "a, b; c", 'say \\"go\\"', "50 %", "it's (ok) [x]")


def _min_cost(prods):
    """Smallest number of expansions a node needs, to close a sentence that is deep enough."""
    cost = {}

    def c(node, seen):
        k = node[0]
        if k == "lit":
            return 0
        if k == "ref":
            n = node[1]
            if n in cost:
                return cost[n]
            if n in seen:
                return 10**6
            return 1 + c(prods[n], seen | {n})
        if k == "seq":
            return sum(c(x, seen) for x in node[1])
        if k == "alt":
            return min(c(x, seen) for x in node[1])
        if k == "opt":
            return 0
        return c(node[1], seen) if node[2] else 0

    for _ in range(3):
        for n in prods:
            cost[n] = 1 + c(prods[n], {n})
    return cost, c


class Generator:
    """Procedures from the productions: at every choice the least used alternative first (the
    coverage drives the walk), past ``max_depth`` the cheapest; deterministic per seed."""

    def __init__(self, prods, seed=0, max_depth=8, budget=200):
        self.prods = prods
        self.rng = random.Random(seed)
        self.max_depth = max_depth
        self.default_budget = budget
        self.out = []
        self.counts = {}  # (production, path) -> uses
        self.uses = {}  # production -> uses
        self.cost, self._c = _min_cost(prods)
        self._costs = {}  # id(node) -> cost (the nodes live as long as the productions)

    def sentence(self, start="Procedure Definition", budget=None):
        self.depth = 0
        self.budget = budget or self.default_budget
        out = self.out = []
        self.emit(("ref", start), start, "", out)
        return out

    def text(self, tokens):
        seps = (" ", " ", " ", "\n", "\n  ", "  ")
        out = []
        for j, t in enumerate(tokens):
            if j:
                out.append(self.rng.choice(seps))
            out.append(t)
        return "".join(out)

    def node_cost(self, node):
        """What closing ``node`` costs at least (``node`` a part of the productions: the cache
        is by identity)."""
        c = self._costs.get(id(node))
        if c is None:
            c = self._costs[id(node)] = self._c(node, frozenset())
        return c

    def _count(self, name, path):
        key = (name, path)
        self.counts[key] = self.counts.get(key, 0) + 1

    def _pick(self, name, options, costs):
        """Index among ``options`` (paths): deep, the cheapest (``costs()`` says what each
        costs); else mostly the least used."""
        if self.depth > self.max_depth or len(self.out) > self.budget:
            # deep or long: close the sentence, still by the least used of the cheap ones
            costs = costs()
            least = min(costs)
            cheap = [k for k, c in enumerate(costs) if c <= least + 2]
            used = [self.counts.get((name, options[k]), 0) for k in cheap]
            j = cheap[used.index(min(used))]
        elif self.rng.random() < 0.7:
            used = [self.counts.get((name, o), 0) for o in options]
            least = min(used)
            j = self.rng.choice([k for k, u in enumerate(used) if u == least])
        else:
            j = self.rng.randrange(len(options))
        self._count(name, options[j])
        return j

    def emit(self, node, name, path, out):
        k = node[0]
        if k == "lit":
            out.extend(node[1].split())
        elif k == "ref":
            n = node[1]
            self.uses[n] = self.uses.get(n, 0) + 1
            if n == "Identifier":
                out.append(self.identifier())
            elif n in LEXICAL:
                out.append(self.lexical(n))
            elif n in NUMERIC:
                self.numeric(n, out)
            else:
                self.depth += 1
                self.emit(self.prods[n], n, "", out)
                self.depth -= 1
        elif k == "seq":
            for j, x in enumerate(node[1]):
                self.emit(x, name, path + ".%d" % j, out)
        elif k == "alt":
            opts = [path + "|%d" % j for j in range(len(node[1]))]
            j = self._pick(name, opts, lambda: [self.node_cost(x) for x in node[1]])
            self.emit(node[1][j], name, opts[j], out)
        elif k == "opt":
            j = self._pick(
                name, [path + "[+]", path + "[-]"], lambda: [self.node_cost(node[1]), 0]
            )
            if j == 0:
                self.emit(node[1], name, path + "[]", out)
        else:
            opts = [path + "{1}", path + "{n}"] + ([path + "{0}"] if node[2] == 0 else [])
            c = self.node_cost(node[1])
            j = self._pick(name, opts, lambda: [c, 2 * c, 0][: len(opts)])
            for _ in range((1, 2 + self.rng.randrange(2), 0)[j]):
                self.emit(node[1], name, path + "{}", out)

    def identifier(self):
        words = [self.rng.choice(FIRST_WORDS)]
        more = self.rng.choice((0, 0, 1, 2))
        self._count("Identifier", (".1{0}", ".1{1}", ".1{n}")[more])
        self.use("Identifier First Word", "Letter")
        for _ in range(more):
            words.append(self.rng.choice(NEXT_WORDS))
            self.use("Identifier Subsequent Word", "Digit" if words[-1][0].isdigit() else "Letter")
        return " ".join(words)

    def use(self, *names):
        """Count the lexical productions a token was written from."""
        for n in names:
            self.uses[n] = self.uses.get(n, 0) + 1

    # the lexical level: one token each, within the ranges the standard's text gives
    def digits(self, lo=1, hi=4):
        self.use("Digit")
        return "".join(self.rng.choice("0123456789") for _ in range(self.rng.randint(lo, hi)))

    def lexical(self, n):
        r = self.rng
        if n in ("String Constant", "Enumerated Constant"):
            s = r.choice(STRINGS)
            self.use("Characters", "Letter")
            return '"%s"' % s
        if n == "Absolute Time Constant":
            y = "%04d" % r.randint(1970, 2099)
            self.use("Year", "Hour", "Minute", "Second", "Fraction Of Second")
            if r.random() < 0.5:
                self.use("Month", "Day Of Month")
                date = "%s-%02d-%02d" % (y, r.randint(1, 12), r.randint(1, 28))
            else:
                self.use("Day")
                date = "%s-%03d" % (y, r.randint(1, 365))
            t = "T%02d:%02d:%02d.%s" % (r.randint(0, 23), r.randint(0, 59), r.randint(0, 59),
                                         self.digits(1, 6))  # fmt: skip
            return date + t + r.choice(("", "Z"))
        if n == "Hexadecimal Constant":
            self.use("Hexadecimal Constant", "Hexadecimal Symbol", "Hexadecimal Digit")
            return "0x" + "".join(r.choice("0123456789ABCDEF") for _ in range(r.randint(1, 8)))
        if n == "Unit Simple Factor":
            out = []
            self.emit(self.prods[n], n, "", out)
            return "".join(out)
        if n == "Unsigned Integer":
            return str(r.randint(1, 4))
        return self.digits()

    def numeric(self, n, out):
        r = self.rng
        sign = r.choice(("", "", "-", "+"))
        if n == "Relative Time Constant":
            if sign:
                self.use("Sign")
            if r.random() < 0.3:
                self._count(n, "|1")
                self.use("Days", "Hour", "Minute", "Second", "Fraction Of Second")
                text = "%s%d:%02d:%02d:%02d:%s" % (sign, r.randint(0, 400), r.randint(0, 23),
                                                   r.randint(0, 59), r.randint(0, 59),
                                                   self.digits(1, 3))  # fmt: skip
            else:
                self._count(n, "|0")
                parts = []
                units = ("d", "h", "min", "s")
                first = r.randrange(4)
                last = r.randint(first, 3)
                for u in units[first : last + 1]:
                    if u == units[last] or r.random() < 0.6:
                        self.use(("Days", "Hours", "Minutes", "Seconds")[units.index(u)])
                        parts.append(self.digits(1, 3) + u)
                if units[last] == "s" and r.random() < 0.4:
                    self.use("Fraction Of Second")
                    parts[-1] = parts[-1][:-1] + "." + self.digits(1, 3) + "s"
                text = sign + "".join(parts)
            out.append(text)
            return
        if n == "Integer Constant" and r.random() < 0.2:
            self._count(n, "|1")
            out.append(self.lexical("Hexadecimal Constant"))
            return
        if n == "Integer Constant":
            self._count(n, "|0")
        if sign:
            self.use("Sign")
        text = sign + self.digits(1, 5)
        if n == "Real Constant":
            if r.random() < 0.6:
                self._count(n, ".")
                text += "." + self.digits(1, 4)
            if r.random() < 0.3:
                self._count(n, "e")
                text += "e" + r.choice(("", "-", "+")) + self.digits(1, 2)
        out.append(text)
        j = self._pick(n, ["[+]", "[-]"], lambda: [self.cost["Engineering Units"], 0])
        if j == 0:
            self.emit(("ref", "Engineering Units"), n, "", out)


# ---------------------------------------------------------------------------------------------
# the reference parser


def keywords(prods):
    """Every word of the grammar's keywords ("in case" gives "in" and "case"), from the
    productions above the lexical level."""
    out = set()
    seen = set()
    below = LEXICAL | NUMERIC | {"Identifier", "Engineering Units"}

    def walk(node):
        k = node[0]
        if k == "lit":
            for w in node[1].split():
                if w[0].isalpha():
                    out.add(w)
        elif k == "ref":
            n = node[1]
            if n not in seen and n not in below:
                seen.add(n)
                walk(prods[n])
        elif k in ("seq", "alt"):
            for x in node[1]:
                walk(x)
        else:
            walk(node[1])

    walk(("ref", "Procedure Definition"))
    return out


def _rule(name):
    return re.sub(r"\W", "_", name.lower())


def _sign(c):
    if c.isalnum():
        return c
    if c == "\\":
        return "\\\\"
    return "[%s]" % ("\\" + c if c in "[]^" else c)


def _regex(prods, node):
    k = node[0]
    if k == "lit":  # a class per sign: Lark reads the escapes of a regular expression itself
        return "".join(_sign(c) for c in node[1])
    if k == "ref":
        return _regex(prods, prods[node[1]])
    if k == "seq":
        return "".join(_regex(prods, x) for x in node[1])
    if k == "alt":  # longest first: the lexer takes the first that matches
        parts = sorted((_regex(prods, x) for x in node[1]), key=len, reverse=True)
        return "(?:%s)" % "|".join(parts)
    if k == "opt":
        return "(?:%s)?" % _regex(prods, node[1])
    return "(?:%s)%s" % (_regex(prods, node[1]), "+" if node[2] else "*")


def lark_grammar(prods, reserved=None):
    """The productions as a Lark grammar: keywords split into words, the lexical productions
    as terminals, identifier words any word but the ``reserved`` ones (by default every
    keyword of the grammar)."""
    lines = []
    terms = {}

    def term(name, pattern):
        t = re.sub(r"\W", "_", name.upper())
        terms[t] = pattern
        return t

    def conv(node):
        k = node[0]
        if k == "lit":
            return " ".join('"%s"' % w.replace("\\", "\\\\").replace('"', '\\"')
                            for w in node[1].split())  # fmt: skip
        if k == "ref":
            n = node[1]
            if n == "Identifier":
                return "identifier"
            if n in LEXICAL:  # a whole word: the first alternative that matches is taken
                return term(n, _regex(prods, prods[n]) + "(?![A-Za-z0-9])")
            return _rule(n)
        if k == "seq":
            return " ".join("(%s)" % conv(x) for x in node[1])
        if k == "alt":
            return " | ".join("(%s)" % conv(x) for x in node[1])
        if k == "opt":
            return "[%s]" % conv(node[1])
        return "(%s)%s" % (conv(node[1]), "+" if node[2] else "*")

    for n, node in prods.items():
        if n in LEXICAL or n == "Identifier":
            continue
        if n in NUMERIC:
            continue
        lines.append("%s: %s" % (_rule(n), conv(node)))
    words = keywords(prods) if reserved is None else reserved
    kw = "|".join(sorted(words, key=len, reverse=True))
    lines.append("identifier: WORD (WORD | DIGITS)*")
    lines.append(r"WORD: /(?!(?:%s)\b)[A-Za-z][A-Za-z0-9_]*/" % kw)
    # a word of digits: '1e5' and '1.5' are numbers, never two words of a name
    lines.append(r"DIGITS: /[0-9]+(?![eE][+-]?[0-9]|\.[0-9]|x[0-9A-F])/")
    d = r"[0-9]+"
    lines.append(r"integer_constant: INTNUM [engineering_units] | HEXADECIMAL_CONSTANT")
    lines.append(r"INTNUM: /[+-]?%s/" % d)
    lines.append(r"real_constant: REALNUM [engineering_units]")
    lines.append(r"REALNUM: /[+-]?%s(?:\.%s)?(?:e[+-]?%s)?/" % (d, d, d))
    lines.append("relative_time_constant: RELTIME")
    # any of days, hours, minutes and seconds in that order, the longest first
    dd, hh, mm, ss = (r"(?:%sd)" % d, r"(?:%sh)" % d, r"(?:%smin)" % d,
                      r"(?:%s(?:\.%s)?s)" % (d, d))  # fmt: skip
    units = "|".join((dd + hh + "?" + mm + "?" + ss + "?", hh + mm + "?" + ss + "?",
                      mm + ss + "?", ss))  # fmt: skip
    colon = ":".join((d, d, d, d, d))
    lines.append(r"RELTIME: /[+-]?(?:%s|%s)/" % (units, colon))
    if "HEXADECIMAL_CONSTANT" not in terms:
        terms["HEXADECIMAL_CONSTANT"] = _regex(prods, prods["Hexadecimal Constant"])
    for t, pattern in terms.items():
        lines.append("%s: /%s/" % (t, pattern.replace("/", "\\/")))
    lines.append("%import common.WS")
    lines.append("%ignore WS")
    return "\n".join(lines) + "\n"


def reference_parser(prods=None, reserved=None):
    from lark import Lark

    text = lark_grammar(prods or productions(), reserved)
    return Lark(text, start="procedure_definition", parser="earley", lexer="dynamic")


# ---------------------------------------------------------------------------------------------
# a run: generated procedures, procedures one token away from them, coverage

GENERATED = 2000  # procedures generated from the grammar, each parsed
CHECKED = 10  # of them also given to the reference parser (it is slow)
MUTANTS = 250  # procedures one token away from a small generated one, given to both
SEED = 2008  # the year of ECSS-E-ST-70-32C


START = "Procedure Definition"
STEP = "procedure initiate and confirm step S main %s; end main end step; end procedure"
FOCUS = (  # (start, the procedure around it, tokens before the walk closes)
    ("Step Statement", STEP, 0),
    ("Flow Control Statement", STEP, 0),
    ("Case Statement", STEP, 800),
    ("Expression", "procedure log %s; end procedure", 0),
    (
        "Predefined Type",
        "procedure initiate and confirm step S declare variable v of type %s"
        " end declare main log v; end main end step; end procedure",
        0,
    ),
)


def mutant(tokens, rng, words):
    """``tokens`` with one token deleted, repeated, swapped with the next or inserted."""
    t = list(tokens)
    j = rng.randrange(len(t))
    m = rng.randrange(4)
    if m == 0:
        del t[j]
    elif m == 1:
        t.insert(j, t[j])
    elif m == 2 and j + 1 < len(t):
        t[j], t[j + 1] = t[j + 1], t[j]
    else:
        t.insert(j, rng.choice(words))
    return " ".join(t)


class Run:
    """What one run of the generator and the reference found (``parse`` is ours)."""

    def __init__(self, parse, syntax_error, reserved, seed=SEED, generated=GENERATED,
                 checked=CHECKED, mutants=MUTANTS):  # fmt: skip
        self.prods = productions()
        self.gen = Generator(self.prods, seed)
        self.refused = []  # (error, text) of generated procedures our parser refused
        self.texts = []
        for j in range(generated):
            # half from the start symbol, half from a statement, an expression or a type in
            # the smallest procedure that holds it, so that deep clauses are reached too
            start, frame, budget = FOCUS[j % 10] if j % 10 < len(FOCUS) else (START, "%s", 0)
            text = frame % self.gen.text(self.gen.sentence(start, budget))
            self.texts.append(text)
            try:
                parse(text)
            except syntax_error as e:
                self.refused.append((e, text))
        ref = reference_parser(self.prods, reserved)
        self.outside = []  # generated procedures the reference refuses (a generator fault)
        for text in self.texts[:checked]:
            if not accepts(ref, text):
                self.outside.append(text)
        small = Generator(self.prods, seed + 1, budget=40)
        rng = random.Random(seed)
        words = sorted(keywords(self.prods)) + [";", ",", "(", ")", ":="]
        self.mutants = mutants
        self.reference_accepts = 0
        self.disagreements = []  # (reference accepts, our error or None, text)
        for _ in range(mutants):
            text = mutant(small.sentence(), rng, words)
            ok = accepts(ref, text)
            self.reference_accepts += ok
            try:
                parse(text)
                ours = None
            except syntax_error as e:
                ours = e
            if ok != (ours is None):
                self.disagreements.append((ok, ours, text))
        self.checked = checked

    def missing(self):
        """Alternatives and optional clauses no generated procedure took."""
        return [c for c in choice_points(self.prods) if self.gen.counts.get(c, 0) == 0]

    def markdown(self):
        points = {}
        for name, path in choice_points(self.prods):
            n = points.setdefault(name, [0, 0])
            n[1] += 1
            n[0] += self.gen.counts.get((name, path), 0) > 0
        lines = [
            "<!-- generated by `python tests/host/pluto_annex_a.py --write` from a grammar run;"
            " do not edit -->",
            "",
            "%d procedures generated from the grammar (seed %d), %d refused by the parser; %d of"
            " them given to the reference parser too, %d refused by it. %d procedures one token"
            " away from generated ones: the reference takes %d, the parser agrees on %d."
            % (len(self.texts), SEED, len(self.refused), self.checked, len(self.outside),
               self.mutants, self.reference_accepts, self.mutants - len(self.disagreements)),
            "",
            "| production | alternatives and optional clauses taken | expansions |",
            "|---|---|---|",
        ]  # fmt: skip
        for name in self.prods:
            if name in points:
                taken = "%d of %d" % tuple(points[name])
            elif name in LEXICAL or name == "Identifier":
                taken = "a token"
            else:
                taken = "one form"
            lines.append("| %s | %s | %d |" % (name, taken, self.gen.uses.get(name, 0)))
        return "\n".join(lines) + "\n"


def accepts(ref, text):
    from lark.exceptions import LarkError

    try:
        ref.parse(text)
        return True
    except LarkError:
        return False


BEGIN = "<!-- annex-a run -->"
END = "<!-- end annex-a run -->"
PAGE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "docs", "pluto.md")


def page_with(table, page):
    head, rest = page.split(BEGIN + "\n", 1)
    return head + BEGIN + "\n" + table + END + rest.split(END, 1)[1]


def main(argv):
    from obsw.pluto.lexer import PlutoSyntaxError
    from obsw.pluto.parser import parse
    from obsw.pluto.syntax import RESERVED

    with open(PAGE) as f:
        page = f.read()
    text = page_with(Run(parse, PlutoSyntaxError, RESERVED).markdown(), page)
    if "--check" in argv:
        print("docs/pluto.md is %s" % ("current" if text == page else "stale"))
        return 0 if text == page else 1
    with open(PAGE, "w") as f:
        f.write(text)
    print("wrote docs/pluto.md")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
