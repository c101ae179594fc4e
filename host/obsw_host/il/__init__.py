"""The interaction layer between processes: CBOR frames over Unix sockets, a name directory.

``SocketTransport(node, directory)`` joins a core ``obsw.il.node.Node`` to the other
processes that use the same directory; see ``transport``.
"""
