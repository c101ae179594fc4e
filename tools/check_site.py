#!/usr/bin/env python3
"""The built documentation site reads from disk (file://): every relative link and asset of
every page names a file that exists, never a folder (which a browser shows as a listing).

check_site.py SITE_DIR    prints the broken links, then 'N passed, N failed' (pages)
"""

import html.parser
import os
import sys
import urllib.parse


class _Links(html.parser.HTMLParser):
    def __init__(self):
        super().__init__()
        self.found = []

    def handle_starttag(self, tag, attrs):
        for name, value in attrs:
            if name in ("href", "src") and value:
                self.found.append(value)


def broken(site, page):
    """The links of ``page`` (a path under ``site``) that do not name a file of the site."""
    parser = _Links()
    with open(os.path.join(site, page), encoding="utf-8") as f:
        parser.feed(f.read())
    out = []
    for link in parser.found:
        url = urllib.parse.urlsplit(link)
        if url.scheme or url.netloc or link.startswith(("#", "mailto:", "data:")):
            continue
        target = os.path.normpath(os.path.join(site, os.path.dirname(page), url.path))
        if not url.path:
            continue
        if not os.path.isfile(target):
            out.append(link)
    return out


def main(argv):
    site = argv[1]
    passed = failed = 0
    for folder, _, files in os.walk(site):
        for name in sorted(files):
            if not name.endswith(".html") or name == "404.html":  # a web server's page only
                continue
            page = os.path.relpath(os.path.join(folder, name), site)
            bad = broken(site, page)
            if bad:
                failed += 1
                print("%s: %s" % (page, ", ".join(sorted(set(bad))[:10])))
            else:
                passed += 1
    print("%d passed, %d failed" % (passed, failed))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
