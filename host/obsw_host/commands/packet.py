"""`obsw packet`: decode and encode space packets and PUS-C packets."""


def add_parser(sub):
    p = sub.add_parser("packet", help="decode or encode space packets", description=__doc__)
    s = p.add_subparsers(dest="action", metavar="ACTION")
    s.required = True
    d = s.add_parser("decode", help="print a packet as JSON", description="Decode a packet.")
    d.add_argument("hex", help="the packet as hexadecimal (spaces allowed)")
    d.set_defaults(func=decode)


def decode(args):
    raise SystemExit("obsw packet decode: not implemented yet")
