"""SpaceCAN: the redundant onboard CAN bus, wire-compatible with LibreCube's spacecan 0.8.1.

Sans-I/O: controller and responder state machines take (bus, can_id, data, now) in and give
frames, events and deadlines out; drivers (python-can on the host, pyb.CAN on a board, the
simulated bus in `obsw.spacecan.sim`) move the frames.
"""
