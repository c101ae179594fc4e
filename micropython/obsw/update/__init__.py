"""Software update packages, read and checked on the OBC and on the reconfiguration module."""
