"""Mistakes in a mission folder: ``Problem`` (one line each) and the ``MissionError`` family.

A problem reads ``FILE: $.json.path: what is wrong; expected ... (did you mean 'writable'?)``.
Every error about a mission is a ``MissionError`` (a ``UserError``: one line each, exit 2):
``ConfigError`` (a mission file the OBC cannot use, ``obsw_host.mission.config``),
``PluginError`` (a component module, ``obsw_host.obc.plugins``), ``PortError``
(``obsw_host.mission.ports``) and ``MissionError.at(file, key, text)`` for an id the mission
does not give (``obsw_host.mission.ids``).
"""

import difflib
import json
import os

from obsw_host.errors import UserError


def display(path):
    """``path`` as the user would type it: relative to the working folder when inside it."""
    try:
        rel = os.path.relpath(path)
    except ValueError:
        return path
    return path if rel.startswith("..") else rel


def json_path(parts):
    """``$.components[0].attributes[1]`` for the keys and indexes ``parts``."""
    out = "$"
    for p in parts:
        if isinstance(p, int):
            out += "[%d]" % p
        elif p.replace("_", "a").isalnum() and not p[:1].isdigit():
            out += "." + p
        else:
            out += "[%s]" % json.dumps(p)
    return out


def short(value, limit=40):
    """A JSON value in a message, cut at ``limit`` characters."""
    text = json.dumps(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def did_you_mean(word, choices):
    """`` (did you mean 'x'?)`` for the closest of ``choices``, or an empty string."""
    if not isinstance(word, str):
        return ""
    found = difflib.get_close_matches(word, [str(c) for c in choices], n=1, cutoff=0.6)
    if not found:
        lower = {str(c).lower(): str(c) for c in choices}
        found = [lower[word.lower()]] if word.lower() in lower else []
    return " (did you mean %r?)" % found[0] if found else ""


class Problem:
    """One mistake: the file, the JSON path in it and the text (what is wrong; expected ...)."""

    __slots__ = ("file", "path", "text")

    def __init__(self, file, path, text):
        self.file = file  # None: the problem is not in one file
        self.path = path if isinstance(path, str) else json_path(path)
        self.text = text

    def __str__(self):
        if self.file is None:
            return "%s: %s" % (self.path, self.text)
        return "%s: %s: %s" % (display(self.file), self.path, self.text)

    def __repr__(self):
        return "Problem(%r)" % str(self)

    def __eq__(self, other):
        return isinstance(other, Problem) and str(self) == str(other)

    def __hash__(self):
        return hash(str(self))


class MissionError(UserError):
    """A mission that cannot be used; ``problems`` lists every mistake found (``Problem``)."""

    def __init__(self, problems):
        self.problems = list(problems)
        super().__init__("\n".join(str(p) for p in self.problems))

    @classmethod
    def at(cls, file, key, text):
        """One problem: ``FILE: KEY: text``."""
        return cls([Problem(file, key, text)])


class ConfigError(MissionError, ValueError):
    """A mission file the OBC cannot use: ``key`` says where (``FILE: KEY: text``)."""

    def __init__(self, key, message, file=None):
        super().__init__([Problem(file, key, message)])
        self.key = key


class PortError(MissionError):
    """A port section or variable that cannot be used; the message names where."""

    def __init__(self, message):
        super().__init__([message])
