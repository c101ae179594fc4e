"""The SDLS key file: security associations and their keys as JSON, kept outside the repository.

    {"format": "obsw-sdls-keys", "version": 1,
     "sas": [{"spi": 1, "vcid": 0, "map_id": null, "key": "<hex, 32 octets>",
              "mac_length": 16, "sn_length": 4, "window": 64, "ahead": null,
              "state": "operational"}]}

``algorithm``: "hmac-sha256" (default: authentication, ``sn_length``-octet sequence number),
"aes-gcm" (authenticated encryption) or "aes-gmac" (authentication only), both AES-256 with the
IV as sequence number (``obsw.frames.sdls_gcm``; ``sn_length`` does not apply, ``reserve`` is
the IV block saved ahead, 64 by default). ``link``: "tc" (default) or "tm" (one SA per TM VC,
GCM only). SPIs are unique across the file.

``sent`` (optional): the highest sequence number (IV) this copy of the key may have sent;
the next frame sends above it. The host keeps it up to date before each number is used.

``map_id`` null: the SA secures every MAP of its VC that has no SA of its own. ``window``: how
far below the highest accepted sequence number a number not seen yet is still taken;
``ahead``: how far above it (null: any). ``state`` is
"operational" (default), "keyed" (loaded but not started), "unkeyed" or "expired" (no
key: nothing is sent or accepted with it).
"""

import binascii
import json

from obsw.frames.sdls import (
    SA_EXPIRED,
    SA_KEYED,
    SA_OPERATIONAL,
    SA_STATE_NAMES,
    SA_UNKEYED,
    SdlsError,
    SecurityAssociation,
    TcSecurity,
)
from obsw.frames.sdls_gcm import GCM, GMAC, GcmSecurityAssociation, TmSecurity

HMAC = "hmac-sha256"

FORMAT = "obsw-sdls-keys"
VERSION = 1
_STATES = {
    "operational": SA_OPERATIONAL,
    "keyed": SA_KEYED,
    "unkeyed": SA_UNKEYED,
    "expired": SA_EXPIRED,
}
_FIELDS = (
    "sent",
    "spi",
    "vcid",
    "map_id",
    "key",
    "mac_length",
    "sn_length",
    "window",
    "ahead",
    "state",
    "algorithm",
    "link",
    "reserve",
)


class KeyFileError(SdlsError):
    """A key file that is not JSON, not of this format, or holds an SA that cannot be."""


def _number(entry, name, default, where):
    v = entry.get(name, default)
    if v is None and name in ("map_id", "ahead"):
        return None
    if not isinstance(v, int) or isinstance(v, bool):
        raise KeyFileError("%s: %s must be an integer, got %r" % (where, name, v))
    return v


def load_sas(text):
    """The SAs of a key file's text; KeyFileError for anything malformed."""
    try:
        doc = json.loads(text)
    except ValueError as e:
        raise KeyFileError("key file is not JSON: %s" % e) from None
    if not isinstance(doc, dict) or doc.get("format") != FORMAT:
        raise KeyFileError("not an %s file" % FORMAT)
    if doc.get("version") != VERSION:
        raise KeyFileError("key file version %r, expected %d" % (doc.get("version"), VERSION))
    entries = doc.get("sas")
    if not isinstance(entries, list):
        raise KeyFileError("key file has no 'sas' list")
    out = []
    for i in range(len(entries)):
        e = entries[i]
        where = "SA #%d" % i
        if not isinstance(e, dict):
            raise KeyFileError("%s is not an object" % where)
        for name in e:
            if name not in _FIELDS:
                raise KeyFileError("%s: unknown field %r" % (where, name))
        state = _STATES.get(e.get("state", "operational"))
        if state is None:
            raise KeyFileError("%s: state %r unknown" % (where, e.get("state")))
        key = None
        if state not in (SA_UNKEYED, SA_EXPIRED):
            try:
                key = binascii.unhexlify(e.get("key", ""))
            except (ValueError, TypeError):
                raise KeyFileError("%s: key is not hex" % where) from None
        algorithm = e.get("algorithm", HMAC)
        link = e.get("link", "tc")
        if algorithm not in (HMAC, GCM, GMAC):
            raise KeyFileError("%s: algorithm %r unknown" % (where, algorithm))
        if link not in ("tc", "tm") or (link == "tm" and algorithm == HMAC):
            raise KeyFileError("%s: link %r with %s" % (where, link, algorithm))
        try:
            if algorithm == HMAC:
                sa = SecurityAssociation(
                    _number(e, "spi", None, where),
                    _number(e, "vcid", None, where),
                    key,
                    _number(e, "map_id", None, where),
                    _number(e, "mac_length", 16, where),
                    _number(e, "sn_length", 4, where),
                    _number(e, "window", 64, where),
                    state,
                    _number(e, "ahead", None, where),
                )
            else:
                sa = GcmSecurityAssociation(
                    _number(e, "spi", None, where),
                    _number(e, "vcid", None, where),
                    key,
                    _number(e, "map_id", None, where),
                    _number(e, "mac_length", 16, where),
                    _number(e, "window", 64, where),
                    state,
                    _number(e, "ahead", None, where),
                    algorithm,
                    _number(e, "reserve", 64, where),
                )
        except SdlsError as err:
            raise KeyFileError("%s: %s" % (where, err)) from None
        # the highest number this copy of the key may have sent (reserved before use, see
        # ``obsw_host.frames.keys``): kept with the key, so losing a state file cannot make
        # the SA send a number (a GCM IV) again
        sent = _number(e, "sent", 0, where)
        if sent < 0:
            raise KeyFileError("%s: sent must be 0 or more, got %d" % (where, sent))
        sa.sn_sent = sa.sn_reserved = sent
        sa.link = link
        for other in out:
            if other.spi == sa.spi:
                raise KeyFileError("%s: SPI %d given twice" % (where, sa.spi))
        out.append(sa)
    return out


def load_security(text, segment_header=True):
    """A TcSecurity holding the SAs of a key file's text."""
    try:
        return TcSecurity([sa for sa in load_sas(text) if sa.link == "tc"], segment_header)
    except KeyFileError:
        raise
    except SdlsError as e:
        raise KeyFileError(str(e)) from None


def load_tm_security(text):
    """A TmSecurity holding the TM SAs of a key file's text (None when it has none)."""
    sas = [sa for sa in load_sas(text) if sa.link == "tm"]
    if not sas:
        return None
    try:
        return TmSecurity(sas)
    except SdlsError as e:
        raise KeyFileError(str(e)) from None


def dump_sas(sas):
    """The key file text of ``sas``."""
    entries = []
    for sa in sas:
        algorithm = getattr(sa, "algorithm", HMAC)
        entry = {
            "spi": sa.spi,
            "vcid": sa.vcid,
            "map_id": sa.map_id,
            "key": "" if sa.key is None else binascii.hexlify(sa.key).decode(),
            "mac_length": sa.mac_length,
            "window": sa.window.size,
            "ahead": sa.window.ahead,
            "state": SA_STATE_NAMES[sa.state],
        }
        if algorithm == HMAC:
            entry["sn_length"] = sa.sn_length
        else:
            entry["algorithm"] = algorithm
            entry["reserve"] = sa.reserve_block
        if sa.link != "tc":
            entry["link"] = sa.link
        sent = max(sa.sn_sent, sa.sn_reserved)
        if sent:
            entry["sent"] = sent
        entries.append(entry)
    return json.dumps({"format": FORMAT, "version": VERSION, "sas": entries})
