"""Reading a mission folder's JSON files and checking them against the shipped JSON Schemas
(draft 2020-12): every schema violation as one ``Problem`` line saying what was expected."""

import json
import re

from jsonschema import Draft202012Validator

from obsw_host.mission import defaults
from obsw_host.mission.errors import Problem, did_you_mean, short

_PATTERNS = {  # what a pattern means, in words
    "^[A-Za-z_][A-Za-z0-9_]*$": "an identifier (letters, digits and '_', not starting with "
    "a digit)",
    "^[A-Za-z0-9][A-Za-z0-9_.-]*$": "a name of letters, digits, '_', '.' and '-'",
    "^[A-Za-z0-9][A-Za-z0-9_.-]{0,63}$": "a name of up to 64 letters, digits, '_', '.' and '-'",
    "^[0-9]+$": "an entity id in decimal digits",
    "^[^:/]+$": "a prefix without ':' or '/' (SAT)",
    "^[^\\s:]+:[0-9]{1,5}$": "HOST:PORT",
}
_REQUIRED = re.compile(r"^'(.*)' is a required property")
_validators = {}


def read_json(path, root=None):
    """(document, problems) of JSON file ``path``: a file that cannot be read, bad JSON or a
    key given twice in one object is a problem (the document is then None)."""
    from obsw_host.mission.folder import MAX_DEPTH, read_text

    try:
        text = read_text(path, root=root)
    except UnicodeDecodeError as e:
        return None, [Problem(path, "$", "not UTF-8 text (%s); expected a JSON file" % e)]
    except OSError as e:
        return None, [Problem(path, "$", "cannot read (%s); expected a JSON file" % e.strerror)]
    from obsw import jsonsafe

    try:
        jsonsafe.check_depth(text, MAX_DEPTH)
    except ValueError as e:
        return None, [Problem(path, "$", "%s; expected a JSON document" % e)]
    repeated = []

    def pairs(items):
        seen = {}
        for k, v in items:
            if k in seen:
                repeated.append(k)
            seen[k] = v
        return seen

    try:
        doc = json.loads(text, object_pairs_hook=pairs)
    except ValueError as e:
        msg = getattr(e, "msg", str(e))
        where = " at line %d column %d" % (e.lineno, e.colno) if hasattr(e, "lineno") else ""
        return None, [Problem(path, "$", "not valid JSON: %s%s; expected a JSON document"
                              % (msg, where))]  # fmt: skip
    return doc, [
        Problem(path, "$", "key %r given twice in one object; expected each key once" % k)
        for k in repeated
    ]


def validator(which):
    """The validator of schema ``which`` (defaults.MISSION_SCHEMA or defaults.SDB_SCHEMA)."""
    v = _validators.get(which)
    if v is None:
        v = _validators[which] = Draft202012Validator(defaults.schema(which))
    return v


def validate(doc, which, file):
    """Every violation of schema ``which`` by ``doc`` as Problems of ``file``, in file order."""
    out = []
    for e in sorted(validator(which).iter_errors(doc), key=lambda e: list(e.absolute_path)):
        out += _problems(e, file)
    return out


def json_type(value):
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "a boolean"
    if isinstance(value, int):
        return "an integer"
    if isinstance(value, float):
        return "a number"
    if isinstance(value, str):
        return "a string"
    if isinstance(value, list):
        return "an array"
    return "an object"


def expected(s):
    """What subschema ``s`` accepts, in words."""
    if "enum" in s:
        return "one of " + ", ".join(short(x) for x in s["enum"])
    if "const" in s:
        return short(s["const"])
    if "anyOf" in s or "oneOf" in s or s.get("type") == "array" and "description" in s:
        return s.get("description", "another value")
    t = s.get("type")
    if t in ("integer", "number"):
        low = s.get("minimum")
        high = s.get("maximum")
        word = "an integer" if t == "integer" else "a number"
        if "exclusiveMinimum" in s:
            return "%s above %s" % (word, s["exclusiveMinimum"])
        if low is not None and high is not None:
            return "%s from %s to %s" % (word, low, high)
        if low is not None:
            return "%s >= %s" % (word, low)
        return word
    if t == "string":
        if "pattern" in s:
            return _PATTERNS.get(s["pattern"]) or s.get("description") or "a string"
        return "a non-empty string" if s.get("minLength") else "a string"
    if t == "boolean":
        return "true or false"
    if t == "object":
        return "an object"
    if t == "array":
        return "an array"
    if isinstance(t, list):
        return " or ".join(t)
    return s.get("description", "another value")


def _problems(e, file):
    path = list(e.absolute_path)
    s = e.schema if isinstance(e.schema, dict) else {}
    v = e.validator
    inst = e.instance
    if v == "additionalProperties" and isinstance(inst, dict):
        allowed = sorted(s.get("properties", {}))
        return [
            Problem(
                file,
                path + [k],
                "unknown key; expected one of %s%s"
                % (", ".join(allowed), did_you_mean(k, allowed)),
            )  # fmt: skip
            for k in inst
            if k not in s.get("properties", {})
        ]
    if v == "required":
        m = _REQUIRED.match(e.message)
        key = m.group(1) if m else "?"
        return [Problem(file, path, "missing key %r; expected an object with %s"
                        % (key, ", ".join(s.get("required", ()))))]  # fmt: skip
    if v == "type":
        text = "%s is %s; expected %s" % (short(inst), json_type(inst), expected(s))
    elif v in ("minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum"):
        text = "%s is out of range; expected %s" % (short(inst), expected(s))
    elif v == "enum":
        text = "%s is not one of the choices; expected %s%s" % (
            short(inst), expected(s), did_you_mean(inst, s["enum"]))  # fmt: skip
    elif v == "const":
        text = "%s; expected %s" % (short(inst), short(s["const"]))
        if path == ["format"] or (not path and v == "const"):
            text += " (`obsw mission upgrade FILE` converts older mission files)"
    elif v == "pattern":
        text = "%s is not usable; expected %s" % (short(inst), expected(s))
    elif v == "propertyNames":
        text = "name %s is not usable; expected %s" % (short(inst), expected(e.validator_value))
    elif v in ("minItems", "maxItems"):
        text = "%d items; expected %s" % (len(inst), _items(s))
    elif v == "uniqueItems":
        text = "an item is repeated; expected each item once"
    elif v == "minProperties":
        text = "empty; expected at least one entry"
    elif v in ("anyOf", "oneOf"):
        choices = [c["enum"] for c in e.validator_value if isinstance(c, dict) and "enum" in c]
        if choices and isinstance(inst, str):
            text = "unknown %s %s; expected %s%s" % (
                path[-1] if path and isinstance(path[-1], str) else "value",
                short(inst),
                s.get("description", "one of " + ", ".join(choices[0])),
                did_you_mean(inst, choices[0]),
            )
        else:
            text = "%s is not usable; expected %s" % (short(inst), expected(s))
    else:
        text = "%s; expected %s" % (e.message, expected(s))
    return [Problem(file, path, text)]


def _items(s):
    low, high = s.get("minItems"), s.get("maxItems")
    if s.get("description"):
        return s["description"]
    if low == high:
        return "exactly %d" % low
    if high is None:
        return "at least %d" % low
    return "%s to %d" % (low or 0, high)
