"""Mission components as plug-ins: the module a mission file names, its interface and class.

The mission file's ``components`` section names them::

    "components": {
      "SolarPanel": {"module": "obsw_host.solar_panel"},
      "Magnetorquer": {"module": "magnetorquer.py", "class": "Torquer", "options": {"coils": 3}}
    }

and ``processes`` lists a component's name where it runs (with ``pus``: in the PUS process;
alone, or with other components: in a process of its own, supervised by the platform manager).

The contract a module keeps:

- ``module`` is a dotted module name on the Python path, or a ``.py`` file relative to the
  mission file;
- the module defines, at its top level, the interaction-layer ``Interface`` whose name is the
  component's name (``Interface("SolarPanel", ...)``);
- it defines a class implementing that interface, named ``class`` (default: the component's
  name); the mission's ``options`` are passed to its constructor as keyword arguments;
- the instance may have ``il_bind(provider)`` (called once provided: its handle to publish
  attributes and emit events), ``alive()`` (False when its work has stopped: the platform
  manager then restarts its process) and ``close()`` (called when its process stops);
- its periodic hook, ``tick(now)``, is called every ``period`` seconds (the mission file's
  ``"period"``, required when the class has ``tick``; ``now`` is ``time.monotonic()``) by the
  loop of the unit that serves it (``obsw_host.obc.ticks``).

The threading rule: the unit calls ``tick``, the operations, the attribute reads and writes
and ``close`` of a component from one thread, its own, one call at a time; a component
publishes (``provider.update``, ``provider.emit``) from those calls only. A component that
needs a thread of its own (a blocking driver) hands what it finds to the next ``tick``
(a ``collections.deque`` is safe to append to from another thread) and publishes there.

Nothing of the module runs until a process builds the component, except its top level when
the topology checks that the interface and the class are there. ``serve`` (``obsw il serve
MODULE``, ``python -m obsw_host.obc.plugins MODULE``) provides any such component in a
process of its own, outside any mission.
"""

import argparse
import importlib
import importlib.util
import json
import os
import signal
import sys

from obsw.il.interface import Interface
from obsw.il.node import Node

from obsw_host.il.transport import SocketTransport
from obsw_host.mission.config import ConfigError


class PluginError(ConfigError):
    """A component module that cannot be used: ``key`` names the mission file's entry."""


def load_module(ref, base_dir=".", key="module"):
    """The module ``ref``: a dotted name, or a ``.py`` file relative to ``base_dir``."""
    if ref.endswith(".py") or os.sep in ref:
        path = os.path.normpath(os.path.join(base_dir, os.path.expanduser(ref)))
        name = "obsw_mission_" + os.path.splitext(os.path.basename(path))[0]
        known = sys.modules.get(name)
        if known is not None and getattr(known, "__file__", None) == path:
            return known
        if not os.path.isfile(path):
            raise PluginError(key, "no file %s" % path)
        spec = importlib.util.spec_from_file_location(name, path)
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        try:
            spec.loader.exec_module(module)
        except Exception as e:
            del sys.modules[name]
            why = "%s fails to load: %s: %s" % (path, type(e).__name__, e)
            raise PluginError(key, why) from None
        return module
    try:
        return importlib.import_module(ref)
    except ImportError as e:
        raise PluginError(key, "cannot import %r (%s)" % (ref, e)) from None
    except Exception as e:
        raise PluginError(key, "%r fails to load: %s: %s" % (ref, type(e).__name__, e)) from None


def interface_of(module, name, key="module"):
    """The top-level ``Interface`` of ``module`` named ``name``."""
    found = [v for v in vars(module).values() if isinstance(v, Interface)]
    for itf in found:
        if itf.name == name:
            return itf
    names = ", ".join(sorted(i.name for i in found)) or "none"
    raise PluginError(
        key, "%s defines no Interface named %r (it defines: %s)" % (module.__name__, name, names)
    )


class Component:
    """One entry of the mission file's ``components``."""

    def __init__(self, name, doc, base_dir="."):
        where = "components.%s" % name
        if not isinstance(doc, dict):
            raise PluginError(where, "expected an object with module, class, options")
        unknown = sorted(set(doc) - {"module", "class", "options", "period"})
        if unknown:
            raise PluginError(where, "unknown key %r (module, class, options, period)" % (
                unknown[0],))  # fmt: skip
        period = doc.get("period")
        if period is not None and (
            isinstance(period, bool) or not isinstance(period, (int, float)) or period <= 0
        ):
            raise PluginError(where + ".period", "expected seconds above 0, got %r" % (period,))
        module = doc.get("module")
        if not isinstance(module, str) or not module:
            raise PluginError(where + ".module", "expected a module name or a .py file")
        cls = doc.get("class", name)
        if not isinstance(cls, str) or not cls:
            raise PluginError(where + ".class", "expected a class name")
        options = doc.get("options", {})
        if not isinstance(options, dict):
            raise PluginError(where + ".options", "expected an object (constructor arguments)")
        self.name = name
        self.module_ref = module
        self.class_name = cls
        self.options = options
        self.period = None if period is None else float(period)
        self.base_dir = base_dir
        self.key = where

    def __repr__(self):
        return "Component(%s, %s:%s)" % (self.name, self.module_ref, self.class_name)

    def module(self):
        return load_module(self.module_ref, self.base_dir, self.key + ".module")

    def interface(self):
        return interface_of(self.module(), self.name, self.key + ".module")

    def implementation_class(self):
        module = self.module()
        cls = getattr(module, self.class_name, None)
        if not isinstance(cls, type):
            raise PluginError(
                self.key + ".class", "%s has no class %r" % (module.__name__, self.class_name)
            )
        return cls

    def check(self):
        """Import the module and find the interface and the class (``PluginError`` if not):
        a class with ``tick`` has a ``period``, a ``period`` has a class with ``tick``."""
        itf, cls = self.interface(), self.implementation_class()
        ticks = callable(getattr(cls, "tick", None))
        if ticks and self.period is None:
            raise PluginError(self.key + ".period", "%s has tick(now) but no period; expected "
                              "the seconds between two ticks" % cls.__name__)  # fmt: skip
        if self.period is not None and not ticks:
            raise PluginError(self.key + ".period", "%s has no tick(now) to call every %g s; "
                              "expected a class with tick, or no period" % (
                                  cls.__name__, self.period))  # fmt: skip
        return itf, cls

    def build(self):
        """``(interface, implementation)``: the class built with the mission's options."""
        itf, cls = self.check()
        try:
            return itf, cls(**self.options)
        except TypeError as e:
            raise PluginError(
                self.key + ".options", "%s(**options): %s" % (cls.__name__, e)
            ) from None


def components(config):
    """The mission's components by name (``config.doc["components"]``)."""
    doc = config.doc.get("components", {})
    if not isinstance(doc, dict):
        raise PluginError("components", 'expected component name -> {"module": ...}')
    return {name: Component(name, entry, config.dir) for name, entry in doc.items()}


def component_for(module_ref, name=None, cls=None, options=None, base_dir=".", period=None):
    """A ``Component`` outside any mission file: ``name`` defaults to the name of the module's
    only ``Interface``."""
    if name is None:
        module = load_module(module_ref, base_dir)
        found = [v for v in vars(module).values() if isinstance(v, Interface)]
        if len(found) != 1:
            names = ", ".join(i.name for i in found) or "none"
            raise PluginError("module", "%s defines %d interfaces: say which component (%s)" % (
                module.__name__, len(found), names))  # fmt: skip
        name = found[0].name
    doc = {"module": module_ref, "options": dict(options or {})}
    if cls:
        doc["class"] = cls
    if period is not None:
        doc["period"] = period
    return Component(name, doc, base_dir)


def serve(component, directory=None, node_name=None, out=None):
    """Provide ``component`` in this process on the interaction layer of ``directory`` until
    SIGTERM or SIGINT (its name is withdrawn then)."""
    from obsw_host.obc.ticks import Ticks

    node = Node(node_name or component.name)
    itf, impl = component.build()
    transport = SocketTransport(node, directory)
    node.provide(itf, impl)
    running = [True]

    def stop(signum, frame):
        running[0] = False
        transport.stop()

    signal.signal(signal.SIGTERM, stop)
    signal.signal(signal.SIGINT, stop)
    if out is not None:
        out("%s served by pid %d at %r" % (itf.name, os.getpid(), transport.address))
    try:
        Ticks([(component, (itf, impl))], out or print).serve(transport, node, lambda: running[0])
    finally:
        transport.close()
        close = getattr(impl, "close", None)
        if close is not None:
            close()
    return 0


def _option(text):
    key, sep, value = text.partition("=")
    if not sep or not key:
        raise argparse.ArgumentTypeError("expected KEY=VALUE, got %r" % text)
    try:
        return key, json.loads(value)
    except ValueError:
        return key, value


def add_serve_arguments(p):
    p.add_argument("module", help="component module: a dotted name or a .py file")
    p.add_argument("--component", help="component name (default: the module's only interface)")
    p.add_argument("--class", dest="cls", help="implementation class (default: the name)")
    p.add_argument("--option", action="append", type=_option, default=[], metavar="KEY=VALUE",
                   help="constructor argument (VALUE as JSON, else text); repeatable")  # fmt: skip
    p.add_argument("--node", help="node name (default: the component's name)")
    p.add_argument("--period", type=float, help="seconds between two tick(now) calls (a "
                   "component with a periodic hook)")  # fmt: skip


def serve_args(args):
    """Serve what ``add_serve_arguments`` parsed; one line and status 2 if it cannot."""
    try:
        component = component_for(args.module, args.component, args.cls, dict(args.option),
                                  period=args.period)  # fmt: skip
        out = None if getattr(args, "quiet", False) else (lambda s: print(s, flush=True))
        return serve(component, args.dir, args.node, out)
    except ConfigError as e:
        print("obsw il serve: %s" % e, file=sys.stderr)
        return 2


def main(argv=None):
    """``python -m obsw_host.obc.plugins MODULE [--dir DIR] ...``: serve one component."""
    p = argparse.ArgumentParser(prog="python -m obsw_host.obc.plugins", description=serve.__doc__)
    add_serve_arguments(p)
    p.add_argument("--dir", help="name directory (default $OBSW_IL_DIR or a temp dir)")
    p.add_argument("--quiet", action="store_true")
    return serve_args(p.parse_args(argv))


if __name__ == "__main__":
    sys.exit(main())
