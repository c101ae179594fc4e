"""User mistakes on the command line, as one line each: ``UserError`` and ``user_message``.

Commands raise ``UserError("what was wrong", expected="what was expected")`` for mistakes they
detect; ``user_message(exc)`` also turns the typed errors the libraries raise for bad input
(missing files, bad JSON, unknown hosts, ports in use, bad hex, unknown names, serial and CAN
devices that are not there) into one line. ``obsw`` prints that line and exits with status 2;
anything else is a fault of the program and keeps its traceback.
"""

import errno
import json
import socket


class UserError(Exception):
    """A mistake of the user: ``message`` says what was wrong, ``expected`` what was expected."""

    def __init__(self, message, expected=None):
        super().__init__(message + ("; expected %s" % expected if expected else ""))
        self.expected = expected


def _file_error(e):
    name = e.filename if e.filename is not None else "?"
    if isinstance(e, FileNotFoundError):
        return "%s: no such file or directory" % name
    if isinstance(e, IsADirectoryError):
        return "%s: is a directory; expected a file" % name
    if isinstance(e, NotADirectoryError):
        return "%s: not a directory; expected a directory" % name
    if isinstance(e, PermissionError):
        return "%s: permission denied" % name
    if isinstance(e, FileExistsError):
        return "%s: already exists" % name
    return None


def _os_error(e):
    if isinstance(e, socket.gaierror):
        return "unknown host (%s); expected a host name or an IP address" % (e.strerror or e)
    if e.errno == errno.EADDRINUSE:
        return "address already in use; another process serves this port (expected a free port)"
    if e.errno == errno.EADDRNOTAVAIL:
        return "cannot bind that address: not an address of this machine"
    if e.errno == errno.ECONNREFUSED:
        return "connection refused: nothing is listening there"
    if e.errno == errno.EAFNOSUPPORT:  # the one unusual family we open: PF_CAN (socketcan)
        return (
            "address family not supported by this machine (no socketcan here?); expected "
            "Linux with the can and can_raw modules loaded, or --interface virtual or "
            "udp_multicast"
        )
    if e.errno == errno.ENODEV:
        return "no such device (%s); expected an interface that exists and is up" % (
            e.strerror or e
        )
    if e.filename is not None:
        return _file_error(e) or "%s: %s" % (e.filename, e.strerror)
    return None


def _library_error(e):
    """Errors of optional libraries (pyserial, python-can), recognised by module and name."""
    module = type(e).__module__ or ""
    if module.startswith("serial"):
        return "serial device: %s" % e
    if module.startswith("can"):
        return "CAN interface: %s" % e
    return None


_LISTINGS = (
    ("parameter", "parameters"),
    ("function", "functions"),
    ("event", "events"),
    ("housekeeping", "hk"),
)


class NoAnswer(TimeoutError):
    """Nothing answered in time; the message says where and what to start (exit status 1)."""


def user_message(e):
    """One line describing user mistake ``e``, or None if ``e`` is a fault of the program."""
    if isinstance(e, TimeoutError):
        return str(e) or "timed out"
    if isinstance(e, UserError):
        return str(e)
    if isinstance(e, json.JSONDecodeError):
        where = getattr(e, "filename", None)
        return "%sbad JSON at line %d column %d: %s" % (
            (where + ": ") if where else "",
            e.lineno,
            e.colno,
            e.msg,
        )
    if isinstance(e, OSError):
        return _os_error(e) or _library_error(e)
    text = _library_error(e)
    if text:
        return text
    if isinstance(e, KeyError):
        text = str(e.args[0]) if e.args else "unknown name"
        for kind, listing in _LISTINGS:
            if text.startswith("no %s " % kind):
                return "%s; expected one of `obsw ground list %s`" % (text, listing)
        return text
    if isinstance(e, ValueError):
        return str(e)
    return None


def hex_bytes(text, what="hex"):
    """The bytes that ``text`` spells in hex (spaces and a 0x prefix allowed), or UserError."""
    import binascii

    digits = "".join(text.split())
    if digits[:2].lower() == "0x":
        digits = digits[2:]
    try:
        if len(digits) % 2:
            raise ValueError
        return binascii.unhexlify(digits)
    except (binascii.Error, ValueError):
        raise UserError(
            "%s %r is not hexadecimal" % (what, text[:40]), expected="an even number of hex digits"
        ) from None


def read_json(path, what="JSON file"):
    """The JSON document in file ``path``; a missing file or bad JSON is a UserError."""
    try:
        with open(path, encoding="utf-8") as f:
            return json.load(f)
    except json.JSONDecodeError as e:
        raise UserError(
            "%s %s: bad JSON at line %d column %d (%s)" % (what, path, e.lineno, e.colno, e.msg),
            expected="a JSON document",
        ) from None
