"""The mission's own components (plug-ins): ``components`` of the mission file.

Contract: ``{"<Name>": {"module": "<dotted.module or file.py in the folder>", "class": "<class,
default Name>", "options": {...}}}`` names a module that declares an interaction-layer
``Interface`` called ``Name`` (a module-level ``obsw.il.interface.Interface``) and a class
implementing it, built as ``cls(**options)``; ``obsw_host/solar_panel.py`` is one. The OBC
provides the object under that interface like a built-in unit.
"""

import importlib
import importlib.util
import os
import sys

from obsw.il.interface import Interface


class PluginError(ValueError):
    """A component plug-in that cannot be used: the message says what was expected; ``key``
    is the entry's key at fault (``module`` or ``class``)."""

    def __init__(self, message, key="module"):
        super().__init__(message)
        self.key = key


def import_module(spec, folder):
    """The module that ``spec`` names: a dotted module, or a ``.py`` file relative to ``folder``
    (imported as ``obsw_mission_components.<stem>``)."""
    if spec.endswith(".py"):
        path = os.path.normpath(os.path.join(folder, spec))
        if not os.path.isfile(path):
            raise PluginError("module file %s not found; expected a .py file in the mission "
                              "folder" % spec)  # fmt: skip
        name = "obsw_mission_components." + os.path.splitext(os.path.basename(path))[0]
        loaded = sys.modules.get(name)
        if loaded is not None and getattr(loaded, "__file__", None) == path:
            return loaded
        mspec = importlib.util.spec_from_file_location(name, path)
        module = importlib.util.module_from_spec(mspec)
        sys.modules[name] = module
        try:
            mspec.loader.exec_module(module)
        except Exception as e:
            del sys.modules[name]
            raise PluginError("%s does not import: %s: %s" % (spec, type(e).__name__, e)) from e
        return module
    try:
        return importlib.import_module(spec)
    except ImportError as e:
        raise PluginError("module %s not found (%s); expected an importable module or a .py "
                          "file in the mission folder" % (spec, e)) from e  # fmt: skip
    except Exception as e:
        raise PluginError("%s does not import: %s: %s" % (spec, type(e).__name__, e)) from e


def interface_of(module, name):
    """The ``Interface`` called ``name`` that ``module`` declares."""
    found = [v for v in vars(module).values() if isinstance(v, Interface)]
    for itf in found:
        if itf.name == name:
            return itf
    raise PluginError(
        "%s declares no Interface named %r (it declares %s); expected the component's name"
        % (module.__name__, name, ", ".join(repr(i.name) for i in found) or "none")
    )


def load(name, spec, folder):
    """(interface, class, options) of component ``name`` whose entry is ``spec``."""
    module = import_module(spec["module"], folder)
    itf = interface_of(module, name)
    cls_name = spec.get("class") or name
    cls = getattr(module, cls_name, None)
    if not isinstance(cls, type):
        raise PluginError("%s has no class %s; expected the class implementing %s"
                          % (spec["module"], cls_name, name), "class")  # fmt: skip
    return itf, cls, dict(spec.get("options") or {})


def build(config, names):
    """(interface, instance) of each of the mission's components ``names``."""
    out = []
    for name in names:
        itf, cls, options = load(name, config.components[name], config.dir)
        out.append((itf, cls(**options)))
    return out


def interfaces(config, names):
    """The interfaces of the mission's components ``names`` (nothing is instantiated)."""
    return [load(n, config.components[n], config.dir)[0] for n in names]
