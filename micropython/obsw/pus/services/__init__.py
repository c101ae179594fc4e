"""PUS service providers and service users, one module per service type (sNN_name.py)."""
