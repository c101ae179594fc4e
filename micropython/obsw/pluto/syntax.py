"""PLUTO parsing at the level of tokens: reserved words, names of several words, object
references with their object types (ECSS-E-ST-70-32C Annex A)."""

from obsw.pluto.lexer import DIGITS, EOF, OP, STR, WORD, PlutoSyntaxError, line_col

# Words that end a name of several words: the keywords that may follow a name or open a
# statement (other keywords of Annex A, such as set, value or data, may be words of names).
RESERVED = set(
    (
        "of with end then do to by is and or timeout raise refer default expect described"
        " until else otherwise in initiate if while for repeat wait log inform main watchdog"
        " confirmation preconditions declare step procedure event variable enumerated between"
        " within ask record array AND OR XOR NOT TRUE FALSE"
    ).split()
)
# Annex A's object types, longest first; a reference may name one before each of its names.
OBJECT_TYPES = (
    ("predefined", "value", "set"),
    ("activity", "statement"),
    ("system", "element"),
    ("reporting", "data"),
    ("variable",),
    ("parameter",),
    ("argument",),
    ("activity",),
    ("event",),
    ("step",),
    ("record",),
    ("array",),
)
_TYPE_FIRST = ("predefined", "activity", "system", "reporting", "variable", "parameter",
               "argument", "event", "step", "record", "array")  # fmt: skip
# Deepest nesting of blocks, parentheses and operators the parser takes: the parser, the
# checker and the interpreter walk the tree recursively, and a board's stack is small.
MAX_NESTING = 12


def _show(tok):
    if tok[0] == EOF:
        return "end of text"
    if tok[0] == STR:
        return 'string "%s"' % tok[1]
    return "'%s'" % (tok[1],)


class TokenParser:
    def __init__(self, tokens):
        self.toks = tokens
        self.i = 0
        self.depth = 0

    def enter(self):
        """One level deeper (a block, a parenthesis, an operator); refused past the limit."""
        self.depth += 1
        if self.depth > MAX_NESTING:
            self.err("nesting deeper than %d levels" % MAX_NESTING)

    # token helpers
    def tok(self, k=0):
        j = self.i + k
        return self.toks[j] if j < len(self.toks) else self.toks[-1]

    def pos(self):
        return self.toks[self.i][2]

    def err(self, msg, p=None):
        raise PlutoSyntaxError(msg, *line_col(self.pos() if p is None else p))

    def at(self, *words):
        for k, w in enumerate(words):
            t = self.tok(k)
            if t[1] != w or t[0] not in (WORD, OP):
                return False
        return True

    def take(self, *words):
        if self.at(*words):
            self.i += len(words)
            return True
        return False

    def expect(self, *words, after=""):
        if not self.take(*words):
            self.err(
                "expected '%s'%s, found %s"
                % (" ".join(words), " " + after if after else "", _show(self.tok()))
            )

    def isop(self, sym):
        t = self.toks[self.i]
        return t[0] == OP and t[1] == sym

    def name(self, what="a name", limit=99):
        """A multi-word identifier: the run of non-reserved words here; a word after the first
        may start with a digit ("Wheel 2", "Heater 2b")."""
        words = []
        end = -1  # where the last word ends (line, column): "2" then "b" glued is one word
        start = self.i
        while self.i - start < limit:
            t = self.toks[self.i]
            k = t[0]
            if k == DIGITS and words:
                pass
            elif k != WORD or t[1] in RESERVED:
                break
            elif t[1] == "save" and self.tok(1)[1] == "context":  # a wait's save context
                break
            if words and t[2] == end:
                words[-1] += t[1]
            else:
                words.append(t[1])
            end = t[2] + len(t[1])
            self.i += 1
        if not words:
            self.err("expected %s, found %s" % (what, _show(self.tok())))
        return " ".join(words)

    def object_type(self):
        """The object type that starts here and is followed by a name, its words taken, or
        None."""
        t = self.toks[self.i]
        if t[0] != WORD or t[1] not in _TYPE_FIRST:
            return None
        for words in OBJECT_TYPES:
            if self.at(*words):
                nxt = self.tok(len(words))
                if nxt[0] == WORD and nxt[1] not in RESERVED:
                    self.i += len(words)
                    return " ".join(words)
        return None

    def object_type_here(self):
        save = self.i
        t = self.object_type()
        self.i = save
        return t is not None

    def ref(self, what="a reference"):
        """Object reference ``[type] name {of [type] name}`` as a mutable node the checker
        resolves: ['r', pos, names, object type of the first name, kind, target]. The types of
        the names after 'of' are read and not kept: the names alone say what they are."""
        p = self.pos()
        otype = self.object_type()
        names = [self.name(what)]
        while self.at("of"):
            self.i += 1
            self.object_type()
            names.append(self.name(what))
        return ["r", p, tuple(names), otype, None, None]
