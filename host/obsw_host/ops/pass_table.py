"""The onboard pass table from predicted passes: what `obsw ops uplink` sends.

``windows(passes)`` turns passes (POSIX seconds, UTC, of any stations) into the table's
windows in onboard time (TAI seconds since 1958, the PUS epoch), each rounded inwards to whole
seconds (the dump never starts before the station can hear it: what goes early is lost and
must be asked for again), ordered, passes of stations that overlap or touch merged into one
window (the spacecraft sees the ground the whole time), at most ``limit`` windows (the first
ones: the table is uplinked again before it runs out).
``table(passes)`` is the ``Passes.load`` argument (``obsw_host.obc.passes.pack_table``).
"""

from obsw_host.pus.tai import TAI_MINUS_UNIX

LIMIT = 64  # obsw.frames.contact.MAX_WINDOWS


def windows(passes, limit=LIMIT, offset=TAI_MINUS_UNIX):
    """``[(aos, los), ..]`` onboard seconds, merged and ordered, at most ``limit``."""
    out = []
    for p in sorted(passes, key=lambda p: p.aos):
        # rounded inwards: the OBC sends nothing before the station can hear it, nor after
        aos, los = int(-(-(p.aos + offset) // 1)), int(p.los + offset)
        if aos >= los:
            continue  # shorter than a whole second inside it: nothing to send in
        if out and aos <= out[-1][1]:
            out[-1][1] = max(out[-1][1], los)
        else:
            out.append([aos, los])
    return [tuple(w) for w in out[:limit]]


def table(passes, limit=LIMIT, offset=TAI_MINUS_UNIX):
    from obsw_host.obc.passes import pack_table

    return pack_table(windows(passes, limit, offset))
