"""The unit kinds an OBC process can run, by name, imported only when a process runs one.

As python-can's ``BACKENDS``: ``UNITS`` maps a kind of the mission file's ``processes`` to
``"module:Class"``. A unit class is built as ``Class(topology, process)`` and has
``start()``, ``stop()`` and ``alive()``. ``cfdp`` and ``obcp`` are features of the ``pus``
unit (services 23 and 18 use them directly), so they name no class of their own. Mission
components (plug-ins) are not kinds: the mission file's ``components`` names them, and each
runs in a ``component`` unit (``obsw_host.obc.plugins``).
"""

import importlib

UNITS = {
    "pus": "obsw_host.obc.units:PusUnit",
    "spacecan": "obsw_host.obc.spacecan_unit:SpaceCanUnit",
    "frames": "obsw_host.obc.frames_unit:FramesUnit",
    "component": "obsw_host.obc.units:ComponentUnit",
}
WITH_PUS = ("cfdp", "obcp")  # run inside the pus unit, in its process
# what `processes` may name, besides the names of the mission's components
KINDS = ("pus", "cfdp", "obcp", "spacecan", "frames")


def unit_class(kind):
    """The class of unit ``kind``, imported now."""
    module, _, name = UNITS[kind].partition(":")
    return getattr(importlib.import_module(module), name)
