"""`obsw keys`: SDLS key material and key management over the link (CCSDS 355.1 extended
procedures): make a mission's key file and key store, build the EP commands (as PDUs, or as
a CLTU signed on the EP SA, SPI 62 on MAP 62) and read the OBC's replies."""

import binascii
import os
import sys


def add_parser(sub):
    p = sub.add_parser(
        "keys", help="SDLS keys: key files, OTAR, key and SA management", description=__doc__
    )
    s = p.add_subparsers(dest="action", metavar="ACTION")
    s.required = True

    x = s.add_parser("init", help="a new key file (and key store with master key 1)")
    x.add_argument("file", help="key file to create (outside any git work tree)")
    x.add_argument(
        "--algorithm", default="aes-gcm", choices=("aes-gcm", "aes-gmac", "hmac-sha256")
    )
    x.add_argument("--vcs", default="0", help="TC VCs with an SA each (comma separated)")
    x.add_argument("--tm-vcs", default="", help="TM VCs with an AES-GCM SA each")
    x.set_defaults(func=init)

    def command(name, help_, *args):
        c = s.add_parser(name, help=help_)
        c.add_argument("--keys", required=True, help="the ground's key file (and its .keystore)")
        for a in args:
            c.add_argument(a[0], **a[1])
        c.add_argument("--cltu", action="store_true", help="print a CLTU signed on the EP SA")
        c.add_argument("--scid", type=lambda v: int(v, 0), default=0x2A, help="spacecraft id")
        c.add_argument("--seq", type=int, default=0, help="frame sequence number N(S)")
        c.set_defaults(func=procedure, procedure=name)

    key_ids = ("ids", {"nargs": "+", "type": int, "help": "key IDs"})
    spi = ("spi", {"type": int, "help": "SPI of the SA"})
    command("otar", "upload new keys wrapped under a master key", (
        "ids", {"nargs": "+", "type": int, "help": "IDs of the new keys (128 and up)"}), (
        "--master", {"type": int, "default": 1, "help": "master key ID (default 1)"}))  # fmt: skip
    command("activate", "activate uploaded keys", key_ids)
    command("deactivate", "deactivate keys", key_ids)
    command("destroy", "erase keys on board", key_ids)
    command("verify", "challenge the OBC to prove it holds keys", key_ids)
    command("inventory", "list the OBC's keys and their states")
    command("start", "start an SA (keyed -> operational)", spi)
    command("stop", "stop an SA (operational -> keyed)", spi)
    command("expire", "expire an SA (keyed -> unkeyed, key erased)", spi)
    command("rekey", "key an unkeyed SA with an active key", spi, ("key_id", {"type": int}))
    command("status", "read an SA's state", spi)
    command("read-arsn", "read an SA's anti-replay sequence number", spi)

    r = s.add_parser("reply", help="decode EP reply PDUs (hex; a TM space packet or bare PDUs)")
    r.add_argument("hex")
    r.set_defaults(func=reply)


def init(args):
    from obsw.frames.sdls_keys import KeyFileError

    from obsw_host.frames import keys

    vcs = [int(v) for v in args.vcs.split(",") if v]
    tm = [int(v) for v in args.tm_vcs.split(",") if v]
    try:
        sas = keys.generate(args.file, vcs, algorithm=args.algorithm, tm_vcids=tm, ep=True)
    except (KeyFileError, OSError) as e:
        print("obsw keys init: %s" % e, file=sys.stderr)
        return 2
    print("%s: %d SAs (%s), EP SA %d on MAP %d; key store %s with master key %d" % (
        args.file, len(sas), args.algorithm, keys.EP_SPI, keys.EP_MAP,
        keys.keystore_path(args.file), keys.MASTER_ID))  # fmt: skip
    return 0


def _b16(v):
    return bytes((v >> 8, v & 0xFF))


def procedure(args):
    from obsw.frames import sdls_ep as ep
    from obsw.frames.sdls_keys import KeyFileError

    from obsw_host.frames import keys

    name = args.procedure
    try:
        store_path = keys.keystore_path(args.keys)
        store = keys.load_keystore(store_path)
        if name == "otar":
            master = store.keys.get(args.master)
            if master is None or master[1] is None:
                raise KeyFileError("no master key %d in %s" % (args.master, store_path))
            new = {}
            for kid in args.ids:
                if kid < ep.MASTER_LIMIT or kid in store.keys:
                    raise KeyFileError("key ID %d is a master ID or taken" % kid)
                new[kid] = os.urandom(32)
            # a fresh random IV per upload: 2**-32 collision odds after 2**32 uploads
            pdu = ep.otar_pdu(args.master, master[1], new, os.urandom(12))
            for kid, key in new.items():
                store.add(kid, key)  # the ground keeps them, pre-active like the OBC
            keys.save_keystore(store_path, store)
        elif name in ("activate", "deactivate", "destroy"):
            tag = {"activate": ep.KEY_ACTIVATE, "deactivate": ep.KEY_DEACTIVATE}.get(
                name, ep.KEY_DESTROY
            )
            pdu = ep.pdu(tag, b"".join(_b16(k) for k in args.ids))
        elif name == "verify":
            value = b""
            for kid in args.ids:
                challenge = os.urandom(16)
                print("challenge %d %s" % (kid, binascii.hexlify(challenge).decode()))
                value += _b16(kid) + challenge
            pdu = ep.pdu(ep.KEY_VERIFY, value)
        elif name == "inventory":
            pdu = ep.pdu(ep.KEY_INVENTORY, b"\x00\x00\xff\xff")
        elif name == "rekey":
            pdu = ep.pdu(ep.SA_REKEY, _b16(args.spi) + _b16(args.key_id))
        else:
            tag = {"start": ep.SA_START, "stop": ep.SA_STOP, "expire": ep.SA_EXPIRE,
                   "status": ep.SA_STATUS, "read-arsn": ep.SA_READ_ARSN}[name]  # fmt: skip
            pdu = ep.pdu(tag, _b16(args.spi))
        if args.cltu:
            from obsw.frames.cltu import encode

            security, keeper = keys.load(args.keys)
            frame = keys.signed_frame(security, args.scid, 0, pdu, keys.EP_MAP, args.seq, True)
            if keeper is not None:
                keeper.save()
            print(binascii.hexlify(encode(frame)).decode())
        else:
            print(binascii.hexlify(pdu).decode())
    except (KeyFileError, OSError) as e:
        print("obsw keys %s: %s" % (name, e), file=sys.stderr)
        return 2
    return 0


def reply(args):
    from obsw.frames.sdls_ep import EpError, describe

    try:
        buf = binascii.unhexlify(args.hex.replace(" ", ""))
        if buf and buf[0] < 0x80 and len(buf) >= 6:  # a space packet: replies follow its header
            buf = buf[6:]
        for line in describe(buf):
            print(line)
    except (ValueError, EpError, IndexError) as e:
        print("obsw keys reply: %s" % e, file=sys.stderr)
        return 2
    return 0
