"""Write docs/pus-coverage.md from the coverage report of the sample OBC (`obsw pus coverage`).

Usage: python tools/pus_coverage_page.py [--check]   (--check: exit 1 if the page is stale)
"""

import os
import sys

from obsw_host.pus.coverage import coverage, markdown, obc_services
from obsw_host.sample import MISSION_DIR

PAGE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "docs", "pus-coverage.md")


def main(argv):
    text = markdown(coverage(obc_services(MISSION_DIR)))
    if "--check" in argv:
        with open(PAGE) as f:
            current = f.read() == text
        print("docs/pus-coverage.md is %s" % ("current" if current else "stale"))
        return 0 if current else 1
    with open(PAGE, "w") as f:
        f.write(text)
    print("wrote docs/pus-coverage.md")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
