"""obsw: open onboard software core (MicroPython subset, also imported by CPython)."""

__version__ = "0.1.0"
