"""`obsw demo`: the whole system simulated on one machine."""


def add_parser(sub):
    p = sub.add_parser("demo", help="run the all-on-one-machine demo", description=__doc__)
    p.set_defaults(func=run)


def run(args):
    from obsw_host import demo

    return demo.main()
