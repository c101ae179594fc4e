"""Where onboard-facing services listen unless configured otherwise: the loopback interface.

Every service that opens a socket for onboard traffic (the PUS application process, the frame
processor, the CFDP entity, the simulated CAN hub) takes its default address from here; binding
another interface is an explicit choice (``--host``), never a default.
"""

DEFAULT_HOST = "127.0.0.1"
