"""JSON from outside with its nesting bounded before the recursive parser sees it."""

import json

MAX_DEPTH = 64  # far more than any database or context file needs; far less than a stack


class JsonDepthError(ValueError):
    """The text nests arrays and objects deeper than allowed."""

    def __init__(self, depth, limit):
        super().__init__("JSON nested deeper than %d levels (at least %d)" % (limit, depth))
        self.depth = depth
        self.limit = limit


def check_depth(text, limit=MAX_DEPTH):
    """Raise JsonDepthError if ``text`` (str or UTF-8 bytes) opens more than ``limit`` arrays
    or objects at once; brackets inside strings do not count. One pass over the octets (bytes
    index in constant time on MicroPython, str characters do not), no recursion."""
    data = text.encode() if isinstance(text, str) else text
    depth = 0
    i, n = 0, len(data)
    while i < n:
        o = data[i]
        if o == 34:  # '"': on to the closing quote
            i = _string_end(data, i + 1)
        elif o == 91 or o == 123:  # "[" "{"
            depth += 1
            if depth > limit:
                raise JsonDepthError(depth, limit)
        elif o == 93 or o == 125:  # "]" "}"
            depth -= 1
        i += 1


def _string_end(data, start):
    """Index of the quote closing a string that opened before ``start`` (len(data) if none):
    a quote after an odd run of backslashes is escaped."""
    j = data.find(b'"', start)
    while j > 0:
        k = j - 1
        while k >= start and data[k] == 92:  # "\\"
            k -= 1
        if (j - 1 - k) % 2 == 0:
            return j
        j = data.find(b'"', j + 1)
    return len(data)


def loads(text, limit=MAX_DEPTH):
    """``json.loads`` of ``text`` (str or UTF-8 bytes) after ``check_depth``; every failure is
    a ValueError (UnicodeError and JsonDepthError included)."""
    check_depth(text, limit)
    if isinstance(text, (bytes, bytearray)):
        text = bytes(text).decode()
    return json.loads(text)
