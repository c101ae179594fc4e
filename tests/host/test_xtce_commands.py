"""The standard services' XTCE commands are walked from the layouts the OBC decodes them with:
each layout in ``command_layouts`` is the very one its service's handler decodes (the handler
is run until it decodes), and each command's entries are that layout's fields in order."""

import importlib
import pkgutil
import xml.etree.ElementTree as ET

import obsw.pus.services as services
import pytest
from obsw.pus.services.base import Service
from obsw.pus.structure import Repeated, Structure
from obsw_host.sample import SDB_PATH
from obsw_host.yamcs import database
from obsw_host.yamcs.command_layouts import COMMANDS, Fixed
from obsw_host.yamcs.xtce import generate

NS = {"x": "http://www.omg.org/spec/XTCE/20180204"}


class Decoded(Exception):
    """Raised by the stand-in request when the handler decodes: carries the layout."""


class _Request:
    data = b""
    app_data = b""

    def decode(self, layout):
        raise Decoded(layout)

    def __getattr__(self, name):
        return _Anything()


class _Anything:
    """What a handler may touch on its service before it decodes (tables, components)."""

    def __getattr__(self, name):
        return _Anything()

    def __call__(self, *args, **kwargs):
        return _Anything()

    def __iter__(self):
        return iter(())


def handlers():
    """{(service, subtype): (service class, method name)} of every standard service."""
    found = {}
    for info in pkgutil.iter_modules(services.__path__):
        module = importlib.import_module("obsw.pus.services." + info.name)
        for cls in vars(module).values():
            if isinstance(cls, type) and issubclass(cls, Service) and cls.HANDLERS:
                for msg_type, name in cls.HANDLERS:
                    found.setdefault(tuple(msg_type), (cls, name))
    return found


def decoded_layout(cls, name):
    """The layout the handler decodes its request with (None: it decodes nothing)."""
    probe = type("Probe", (cls,), {"__getattr__": lambda self, n: _Anything()})
    obj = probe.__new__(probe)
    try:
        result = getattr(cls, name)(obj, _Request())
        if hasattr(result, "send"):  # a coroutine: run it to its first decode
            result.send(None)
    except Decoded as d:
        return d.args[0]
    return None


HANDLERS = handlers()


@pytest.mark.parametrize("name, msg_type, layout", [c[:3] for c in COMMANDS])
def test_each_command_walks_the_layout_its_handler_decodes(name, msg_type, layout):
    cls, method = HANDLERS[tuple(msg_type)]
    used = decoded_layout(cls, method)
    assert used is not None, "%s.%s decodes nothing" % (cls.__name__, method)
    if layout.fields:
        assert used is layout, "%s: %s.%s decodes another layout" % (name, cls.__name__, method)
    else:
        assert not used.fields


def flat(fields, arguments):
    """The entry names the walk gives: a group as its count, then one item (or none)."""
    out = []
    for fname, ftype in fields:
        spec = arguments.get(fname, fname)
        if isinstance(ftype, Repeated):
            out.append("count")
            if not isinstance(spec, Fixed):
                item = ftype.item
                item = item.fields if isinstance(item, Structure) else item
                out += flat(item if isinstance(item, list) else [(fname, item)], arguments)
        elif hasattr(ftype, "code") and not isinstance(spec, Fixed):  # CUC: seconds, fraction
            out += [fname + "_seconds", fname + "_fraction"]
        else:
            out.append(getattr(spec, "name", spec) if not isinstance(spec, Fixed) else fname)
    return out


@pytest.fixture(scope="module")
def pus_commands():
    root = ET.fromstring(generate(database.load(SDB_PATH)))
    pus = root.find("x:SpaceSystem[@name='PUS']", NS)
    return {c.get("name"): c for c in pus.iter("{%s}MetaCommand" % NS["x"])}


@pytest.mark.parametrize("command", COMMANDS, ids=[c[0] for c in COMMANDS])
def test_each_command_has_the_layouts_fields_in_order(pus_commands, command):
    name, msg_type, layout, _, arguments = command
    cmd = pus_commands[name]
    assigns = {
        a.get("argumentName"): int(a.get("argumentValue"))
        for a in cmd.iter("{%s}ArgumentAssignment" % NS["x"])
    }
    assert (assigns["service"], assigns["subtype"]) == tuple(msg_type)
    entries = cmd.find("x:CommandContainer/x:EntryList", NS)
    names = [e.get("name") or e.get("argumentRef") for e in entries]
    names = ["count" if n == "n" or n.endswith("_count") else n for n in names]
    assert names == flat(layout.fields, arguments)
