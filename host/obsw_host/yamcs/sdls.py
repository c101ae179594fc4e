"""Yamcs' own SDLS (``org.yamcs.security.sdls``, AES-256-GCM) configured from our key file.

``secure_links(links, key_path, etc)`` takes the dataLinks of a ``frames`` instance and the
mission's SDLS key file, writes each AES-GCM SA's key as the raw 32-octet file Yamcs reads
(``etc/sdls/spi-N.key``, readable by its owner only) and adds to the links the ``encryption``
list and, per virtual channel, ``encryptionSpi`` (TC) or ``encryptionSpis`` (TM). Yamcs'
implementation is authenticated encryption only: HMAC and GMAC SAs of the file are left out,
and a VC whose only SA is of that kind is an error (Yamcs could not talk on it).
"""

import os

from obsw.frames.sdls import SA_OPERATIONAL
from obsw.frames.sdls_gcm import GCM
from obsw.frames.sdls_keys import KeyFileError, load_sas

FACTORY = "org.yamcs.security.sdls.SecurityAssociationAes256Gcm128Factory"
TM_WINDOW = 1024  # Yamcs' anti-replay window on TM IVs: lost frames and a reserved IV block


def _key_file(etc, sa):
    folder = os.path.join(etc, "sdls")
    os.makedirs(folder, mode=0o700, exist_ok=True)
    path = os.path.join(folder, "spi-%d.key" % sa.spi)
    fd = os.open(path + ".tmp", os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
    with os.fdopen(fd, "wb") as f:
        f.write(sa.key)
    os.replace(path + ".tmp", path)
    return os.path.join("etc", "sdls", "spi-%d.key" % sa.spi)


def _entry(etc, sa, downlink):
    args = {"keyFile": _key_file(etc, sa)}
    if downlink:
        args.update({"verifySeqNum": True, "seqNumWindow": TM_WINDOW})
    return {"spi": sa.spi, "class": FACTORY, "args": args}


def secure_links(links, key_path, etc):
    """Add Yamcs SDLS to the ``tc_frames`` and ``tm_frames`` links of ``links`` (in place)
    from the key file at ``key_path``; returns {"tc": {vcid: spi}, "tm": {vcid: spi}}."""
    from obsw_host.frames.keys import read_key_file

    sas = [sa for sa in load_sas(read_key_file(key_path)) if sa.state == SA_OPERATIONAL]
    chosen = {"tc": {}, "tm": {}}
    for sa in sorted(sas, key=lambda s: s.spi):
        if sa.map_id is None and sa.vcid not in chosen[sa.link]:
            chosen[sa.link][sa.vcid] = sa
    for link in links:
        downlink = link.get("name") == "tm_frames"
        if link.get("name") not in ("tc_frames", "tm_frames"):
            continue
        way = "tm" if downlink else "tc"
        entries = []
        for vc in link["virtualChannels"]:
            sa = chosen[way].get(vc["vcId"])
            if sa is None:
                if way == "tc":
                    raise KeyFileError("%s: no SA for TC VC %d" % (key_path, vc["vcId"]))
                continue
            if sa.algorithm != GCM:
                raise KeyFileError(
                    "%s: SA %d is %s; Yamcs speaks AES-GCM only" % (key_path, sa.spi, sa.algorithm)
                )
            if downlink:
                vc["encryptionSpis"] = [sa.spi]
            else:
                vc["encryptionSpi"] = sa.spi
            if all(e["spi"] != sa.spi for e in entries):
                entries.append(_entry(etc, sa, downlink))
        if entries:
            link["encryption"] = entries
    return {way: {v: sa.spi for v, sa in chosen[way].items()} for way in chosen}
