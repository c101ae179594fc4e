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
DIGITS = "d"  # a run of decimal digits, value its text: an integer, or a word of a name


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


_KINDS = WORD + NUM + STR + OP + ABST + RELT + EOF + DIGITS


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


# One class per ASCII octet: the lexer works on the UTF-8 octets of the source, because
# MicroPython finds the i-th character of a str by walking from its start (a lexer indexing a
# str is quadratic there) while indexing bytes is constant-time. Letters are ASCII letters on
# both interpreters; any other octet >= 128 is only allowed inside strings and comments.
_OTHER, _SPACE, _NL, _DIGIT, _LETTER, _UNDER, _QUOTE, _OP = 0, 1, 2, 3, 4, 5, 6, 7


def _classes():
    t = bytearray(256)
    for c in b" \t\r\f":
        t[c] = _SPACE
    t[10] = _NL
    for c in range(48, 58):
        t[c] = _DIGIT
    for c in range(26):
        t[65 + c] = t[97 + c] = _LETTER
    t[95] = _UNDER
    t[34] = _QUOTE
    for c in _OPS1.encode():
        t[c] = _OP
    return bytes(t)


_CLASS = _classes()
_OP2 = {}
for _o in _OPS2:
    _OP2[_o.encode()] = _o
_SLASH, _BACKSLASH, _QUOTE_OCTET, _NEWLINE = 47, 92, 34, 10


def _char_at(b, i):
    """The character whose UTF-8 encoding starts at octet ``i`` (for messages)."""
    k = 1
    while i + k < len(b) and k < 4 and b[i + k] & 0xC0 == 0x80:
        k += 1
    try:
        return b[i : i + k].decode()
    except UnicodeError:
        return "\\x%02x" % b[i]


def _utf8(src):
    """``src`` as UTF-8; a character UTF-8 cannot hold (a lone surrogate) is a syntax error
    at its line and column, not a UnicodeError."""
    try:
        return src.encode()
    except UnicodeError:
        line, col = 1, 1
        for c in src:
            if 0xD800 <= ord(c) <= 0xDFFF:
                break
            if c == "\n":
                line, col = line + 1, 1
            else:
                col += 1
        raise PlutoSyntaxError(
            "character %r is not Unicode text (a lone surrogate)" % c, line, col
        ) from None


def tokenize(src, compact=False):
    """List of (kind, value, pos) tuples ending with an EOF token (``compact``: a Tokens of
    them); raises PlutoSyntaxError. Columns count characters."""
    b = _utf8(src) if isinstance(src, str) else bytes(src)
    cls = _CLASS
    out = Tokens(len(b) // 4 + 8) if compact else []
    i, n = 0, len(b)
    line, start = 1, 0  # start: where the line begins, moved on by one per UTF-8 continuation
    after_num = False
    seen = {}  # one string object per distinct word keeps the token list small
    while i < n:
        o = b[i]
        k = cls[o]
        if k == _NL:
            line, start, i = line + 1, i + 1, i + 1
            after_num = False
            continue
        if k == _SPACE:
            i += 1
            after_num = False
            continue
        p = pos(line, i - start + 1)
        if o == _SLASH and i + 1 < n and b[i + 1] == _SLASH:
            while i < n and b[i] != _NEWLINE:
                i += 1
            continue
        if k == _DIGIT:
            i = _number(b, i, n, out, p)
            after_num = True
            continue
        if k == _LETTER or k == _UNDER:
            j = i + 1
            if after_num:  # "10s", "1d2h": a unit glued to its number holds letters only
                while j < n and cls[b[j]] == _LETTER:
                    j += 1
            else:
                while j < n and _DIGIT <= cls[b[j]] <= _UNDER:
                    j += 1
            w = b[i:j].decode()
            out.append((WORD, seen.setdefault(w, w), p))
            i = j
            after_num = False
            continue
        after_num = False
        if k == _QUOTE:
            j = i + 1
            buf = bytearray()
            while j < n and b[j] != _QUOTE_OCTET:
                if b[j] == _BACKSLASH and j + 1 < n:
                    j += 1
                o = b[j]
                if o == _NEWLINE:
                    break
                if o & 0xC0 == 0x80:
                    start += 1
                buf.append(o)
                j += 1
            if j >= n or b[j] != _QUOTE_OCTET:
                raise PlutoSyntaxError("unterminated string", *line_col(p))
            out.append((STR, buf.decode(), p))
            i = j + 1
            continue
        op = _OP2.get(b[i : i + 2])  # "!=" starts with an octet that is no operator alone
        if op is not None:
            out.append((OP, op, p))
            i += 2
            continue
        if k == _OP:
            out.append((OP, chr(o), p))
            i += 1
            continue
        raise PlutoSyntaxError("unexpected character %r" % _char_at(b, i), *line_col(p))
    out.append((EOF, None, pos(line, i - start + 1)))
    return out


def _digits(b, i, n):
    j = i
    while j < n and 48 <= b[j] <= 57:
        j += 1
    return j


def _digit_at(b, j):
    return j < len(b) and 48 <= b[j] <= 57


def _text(b, i, j):
    return b[i:j].decode()


_MAX_DIGITS = 40  # a 64-bit integer has 20 digits; a real 17 significant ones and an exponent


def _number(b, i, n, out, p):
    if b[i : i + 2] in (b"0x", b"0X"):
        j = i + 2
        while j < n and b[j] in b"0123456789abcdefABCDEF":
            j += 1
        if j == i + 2:
            raise PlutoSyntaxError("hexadecimal constant needs digits", *line_col(p))
        if j - i - 2 > 16:
            raise PlutoSyntaxError("hexadecimal constant longer than 64 bits", *line_col(p))
        out.append((NUM, int(_text(b, i + 2, j), 16), p))
        return j
    j = _digits(b, i, n)
    if b[j : j + 1] == b"-" and j - i == 4 and _digit_at(b, j + 1):
        k = j + 1
        while k < n and b[k] in b"0123456789-:.TZ":
            k += 1
        try:
            out.append((ABST, parse_iso(_text(b, i, k)), p))
        except UnitError:
            raise PlutoSyntaxError(
                "malformed absolute time %r" % _text(b, i, k), *line_col(p)
            ) from None
        return k
    if (
        b[j : j + 1] == b":"
        and _digit_at(b, j + 1)
        and _digit_at(b, j + 2)
        and b[j + 3 : j + 4] == b":"
    ):
        k = j
        while k < n and b[k] in b"0123456789:.":
            k += 1
        parts = _text(b, i, k).split(":")
        if len(parts) not in (4, 5) or not _relative_parts(parts):
            raise PlutoSyntaxError("malformed relative time %r" % _text(b, i, k), *line_col(p))
        v = int(parts[0]) * 86400 + int(parts[1]) * 3600 + int(parts[2]) * 60 + int(parts[3])
        if len(parts) == 5 and parts[4]:
            v += int(parts[4]) / 10 ** len(parts[4])
        out.append((RELT, v, p))
        return k
    real = False
    if b[j : j + 1] == b"." and _digit_at(b, j + 1):
        j = _digits(b, j + 1, n)
        real = True
    if b[j : j + 1] in (b"e", b"E"):
        k = j + 1
        if b[k : k + 1] in (b"+", b"-"):
            k += 1
        if _digit_at(b, k):
            j = _digits(b, k, n)
            real = True
    if j - i > _MAX_DIGITS:
        raise PlutoSyntaxError(
            "numeric constant of %d characters, at most %d" % (j - i, _MAX_DIGITS), *line_col(p)
        )
    if not real:  # "Wheel 2" names a wheel: the parser decides what the digits are
        out.append((DIGITS, _text(b, i, j), p))
        return j
    v = float(_text(b, i, j))
    if v - v != 0:  # inf: beyond the largest real
        raise PlutoSyntaxError("real constant out of range: %s" % _text(b, i, j), *line_col(p))
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
