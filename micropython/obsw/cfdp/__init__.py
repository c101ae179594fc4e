"""CFDP (CCSDS 727.0-B-5): PDUs, class 1 and class 2 procedures, filestore interface."""
