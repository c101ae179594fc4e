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
    """Raise JsonDepthError if ``text`` (str) opens more than ``limit`` arrays or objects at
    once; brackets inside strings do not count. One pass, no recursion."""
    depth = 0
    in_string = False
    escaped = False
    for c in text:
        if in_string:
            if escaped:
                escaped = False
            elif c == "\\":
                escaped = True
            elif c == '"':
                in_string = False
        elif c == '"':
            in_string = True
        elif c == "[" or c == "{":
            depth += 1
            if depth > limit:
                raise JsonDepthError(depth, limit)
        elif c == "]" or c == "}":
            depth -= 1


def loads(text, limit=MAX_DEPTH):
    """``json.loads`` of ``text`` (str or UTF-8 bytes) after ``check_depth``; every failure is
    a ValueError (UnicodeError and JsonDepthError included)."""
    if isinstance(text, (bytes, bytearray)):
        text = bytes(text).decode()
    check_depth(text, limit)
    return json.loads(text)
