"""PLUTO lexer: words, numbers, strings, time literals and operators, each with line and column."""

from obsw.pluto.units import UnitError, isdigits, parse_iso

# Token kinds
WORD = "w"
NUM = "n"
STR = "s"
OP = "o"
ABST = "t"  # absolute time literal, value in seconds since the Unix epoch
RELT = "r"  # colon-form relative time literal (d:hh:mm:ss[:fff]), value in seconds
EOF = "e"

_OPS2 = (":=", "**", "<=", ">=", "!=")
_OPS1 = "=<>+-*/(),;:[].^%"


class PlutoError(ValueError):
    """A procedure rejected at load time; ``kind`` is syntax_error, unknown_reference or
    type_error, ``line`` and ``col`` count from 1."""

    kind = "error"

    def __init__(self, msg, line=0, col=0):
        super().__init__(msg)
        self.msg = msg
        self.line = line
        self.col = col

    def __str__(self):
        return "line %d, column %d: %s" % (self.line, self.col, self.msg)


class PlutoSyntaxError(PlutoError):
    kind = "syntax_error"


def pos(line, col):
    return (line << 12) | (col if col < 4096 else 4095)


def line_col(p):
    return p >> 12, p & 4095


def _isword(c):
    return c.isalpha() or c == "_"


_KINDS = WORD + NUM + STR + OP + ABST + RELT + EOF


class Tokens:
    """A token list in two preallocated columns, kind and position packed into one small int
    (a board's heap holds a long procedure's tokens in 8 bytes each instead of a tuple each, in
    two blocks that do not fragment it); indexing gives (kind, value, pos)."""

    def __init__(self, capacity):
        self.codes = [0] * capacity
        self.values = [None] * capacity
        self.n = 0

    def append(self, token):
        code = (token[2] << 3) | _KINDS.index(token[0])
        if self.n < len(self.codes):
            self.codes[self.n] = code
            self.values[self.n] = token[1]
        else:
            self.codes.append(code)
            self.values.append(token[1])
        self.n += 1

    def __len__(self):
        return self.n

    def __getitem__(self, j):
        if j < 0:
            j += self.n
        if not 0 <= j < self.n:
            raise IndexError(j)
        code = self.codes[j]
        return _KINDS[code & 7], self.values[j], code >> 3

    def __iter__(self):
        for j in range(self.n):
            yield self[j]


def tokenize(src, compact=False):
    """List of (kind, value, pos) tuples ending with an EOF token (``compact``: a Tokens of
    them); raises PlutoSyntaxError."""
    out = Tokens(len(src) // 4 + 8) if compact else []
    i, n = 0, len(src)
    line, start = 1, 0
    after_num = False
    seen = {}  # one string object per distinct word keeps the token list small
    while i < n:
        c = src[i]
        if c == "\n":
            line, start, i = line + 1, i + 1, i + 1
            after_num = False
            continue
        if c in " \t\r\f":
            i += 1
            after_num = False
            continue
        p = pos(line, i - start + 1)
        if c == "/" and src[i + 1 : i + 2] == "/":
            while i < n and src[i] != "\n":
                i += 1
            continue
        if isdigits(c):
            i = _number(src, i, n, out, p)
            after_num = True
            continue
        if _isword(c):
            j = i + 1
            if after_num:  # "10s", "1d2h": a unit glued to its number holds letters only
                while j < n and src[j].isalpha():
                    j += 1
            else:
                while j < n and (src[j].isalpha() or isdigits(src[j]) or src[j] == "_"):
                    j += 1
            w = src[i:j]
            out.append((WORD, seen.setdefault(w, w), p))
            i = j
            after_num = False
            continue
        after_num = False
        if c == '"':
            j = i + 1
            buf = []
            while j < n and src[j] != '"':
                if src[j] == "\\" and j + 1 < n:
                    j += 1
                if src[j] == "\n":
                    break
                buf.append(src[j])
                j += 1
            if j >= n or src[j] != '"':
                raise PlutoSyntaxError("unterminated string", *line_col(p))
            out.append((STR, "".join(buf), p))
            i = j + 1
            continue
        two = src[i : i + 2]
        if two in _OPS2:
            out.append((OP, two, p))
            i += 2
            continue
        if c in _OPS1:
            out.append((OP, c, p))
            i += 1
            continue
        raise PlutoSyntaxError("unexpected character %r" % c, *line_col(p))
    out.append((EOF, None, pos(line, i - start + 1)))
    return out


def _digits(src, i, n):
    j = i
    while j < n and isdigits(src[j]):
        j += 1
    return j


_MAX_DIGITS = 40  # a 64-bit integer has 20 digits; a real 17 significant ones and an exponent


def _number(src, i, n, out, p):
    if src[i] == "0" and src[i + 1 : i + 2] in ("x", "X"):
        j = i + 2
        while j < n and src[j] in "0123456789abcdefABCDEF":
            j += 1
        if j == i + 2:
            raise PlutoSyntaxError("hexadecimal constant needs digits", *line_col(p))
        if j - i - 2 > 16:
            raise PlutoSyntaxError("hexadecimal constant longer than 64 bits", *line_col(p))
        out.append((NUM, int(src[i + 2 : j], 16), p))
        return j
    j = _digits(src, i, n)
    if src[j : j + 1] == "-" and j - i == 4 and isdigits(src[j + 1 : j + 2]):
        k = j + 1
        while k < n and (isdigits(src[k]) or src[k] in "-:.TZ"):
            k += 1
        try:
            out.append((ABST, parse_iso(src[i:k]), p))
        except UnitError:
            raise PlutoSyntaxError("malformed absolute time %r" % src[i:k], *line_col(p)) from None
        return k
    if src[j : j + 1] == ":" and isdigits(src[j + 1 : j + 3]) and src[j + 3 : j + 4] == ":":
        k = j
        while k < n and (isdigits(src[k]) or src[k] in ":."):
            k += 1
        parts = src[i:k].split(":")
        if len(parts) not in (4, 5) or not _relative_parts(parts):
            raise PlutoSyntaxError("malformed relative time %r" % src[i:k], *line_col(p))
        v = int(parts[0]) * 86400 + int(parts[1]) * 3600 + int(parts[2]) * 60 + int(parts[3])
        if len(parts) == 5 and parts[4]:
            v += int(parts[4]) / 10 ** len(parts[4])
        out.append((RELT, v, p))
        return k
    real = False
    if src[j : j + 1] == "." and isdigits(src[j + 1 : j + 2]):
        j = _digits(src, j + 1, n)
        real = True
    if src[j : j + 1] in ("e", "E"):
        k = j + 1
        if src[k : k + 1] in ("+", "-"):
            k += 1
        if isdigits(src[k : k + 1]):
            j = _digits(src, k, n)
            real = True
    if j - i > _MAX_DIGITS:
        raise PlutoSyntaxError(
            "numeric constant of %d characters, at most %d" % (j - i, _MAX_DIGITS), *line_col(p)
        )
    v = float(src[i:j]) if real else int(src[i:j])
    if real and (v - v != 0):  # inf: beyond the largest real
        raise PlutoSyntaxError("real constant out of range: %s" % src[i:j], *line_col(p))
    out.append((NUM, v, p))
    return j


def _relative_parts(parts):
    """d:hh:mm:ss[:fff]: digits only, hours, minutes and seconds in range."""
    for k, part in enumerate(parts):
        if not part or not isdigits(part) or len(part) > 9:
            return False
        if k in (1, 2, 3) and (len(part) != 2 or int(part) > (23, 59, 59)[k - 1]):
            return False
    return True
