"""On-board time from the host clock: TAI seconds since 1958-01-01 (no other import, so that
a ground command reads it without loading the on-board process)."""

import time

TAI_MINUS_UNIX = 378691200 + 37  # seconds from 1958-01-01 TAI to 1970-01-01 UTC, now


def tai_now():
    """On-board time: TAI seconds since 1958-01-01 from the host clock."""
    return time.time() + TAI_MINUS_UNIX
