"""``python -m obsw_host.obc [CONFIG] [--process NAME]``: what ``obsw obc serve`` runs."""

import sys

from obsw_host.commands.obc import main

if __name__ == "__main__":
    sys.exit(main())
