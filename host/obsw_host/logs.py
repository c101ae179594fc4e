"""Logging of the host processes: one format (UTC times), the level from ``obsw --log-level`` or
``$OBSW_LOG_LEVEL``, inherited by the processes they start (the OBC's platform manager's)."""

import logging
import os
import sys
import time

LEVELS = ("debug", "info", "warning", "error")
ENV = "OBSW_LOG_LEVEL"


class UtcFormatter(logging.Formatter):
    """Log times in UTC, ISO 8601 with milliseconds and a Z."""

    converter = time.gmtime

    def formatTime(self, record, datefmt=None):
        stamp = time.strftime("%Y-%m-%dT%H:%M:%S", self.converter(record.created))
        return "%s.%03dZ" % (stamp, record.msecs)


def setup(level=None):
    """Log to stderr at ``level`` (default ``$OBSW_LOG_LEVEL``, else info); children inherit it."""
    level = (level or os.environ.get(ENV) or "info").lower()
    if level not in LEVELS:
        level = "info"
    os.environ[ENV] = level
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(UtcFormatter("%(asctime)s %(levelname)s %(name)s: %(message)s"))
    logging.basicConfig(level=getattr(logging, level.upper()), handlers=[handler], force=True)
