"""The interaction layer: queues, component interfaces, providers, proxies and a name registry.

Import what you need from the submodules (``obsw.il.queue``, ``obsw.il.interface``,
``obsw.il.node``, ...); this package file stays empty so a board only loads what it uses.
"""
