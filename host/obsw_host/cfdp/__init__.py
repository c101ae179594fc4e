"""CFDP on the host: a filestore rooted in one directory and a CFDP entity over UDP carrying
PDUs in space packets."""
