#!/usr/bin/env python3
"""Write the key tables of docs/mission.md from the shipped JSON Schemas (one row per key).

python tools/mission_reference.py           rewrite the tables between their markers
python tools/mission_reference.py --check   exit 1 if the page and the schemas disagree
"""

import json
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [os.path.join(ROOT, "micropython"), os.path.join(ROOT, "host")]

from obsw_host.mission import defaults  # noqa: E402
from obsw_host.mission.schema import expected  # noqa: E402

PAGE = os.path.join(ROOT, "docs", "mission.md")
TABLES = {"mission": defaults.MISSION_SCHEMA, "sdb": defaults.SDB_SCHEMA}


def _resolve(root, node):
    while isinstance(node, dict) and "$ref" in node:
        ref = node["$ref"].rsplit("/", 1)[1]
        merged = dict(root["$defs"][ref])
        merged.update({k: v for k, v in node.items() if k != "$ref"})
        node = merged
    return node


def rows(root, node, path):
    """(key path, accepts, default, description) of ``node`` and everything under it."""
    node = _resolve(root, node)
    out = []
    if path:
        default = json.dumps(node["default"]) if "default" in node else ""
        what = expected(node) if node.get("type") != "object" or "properties" in node else (
            "an object")  # fmt: skip
        text = node.get("description", "")
        if what == text:
            text = ""
        out.append((path, what, default, text))
    for key, child in node.get("properties", {}).items():
        if key == "$schema" and path:
            continue
        out += rows(root, child, "%s.%s" % (path, key) if path else key)
    extra = node.get("additionalProperties")
    if isinstance(extra, dict):
        out += rows(root, extra, "%s.<name>" % path)
    items = node.get("items")
    if isinstance(items, dict):
        out += rows(root, items, "%s[]" % path)
    return out


def table(which):
    root = defaults.schema(TABLES[which])
    lines = ["| key | accepts | default | meaning |", "|---|---|---|---|"]
    for path, what, default, text in rows(root, root, ""):
        cells = ["`%s`" % path, what, "`%s`" % default if default else "", text]
        lines.append("| %s |" % " | ".join(c.replace("|", "\\|") for c in cells))
    return "\n".join(lines)


def render(page):
    for which in TABLES:
        start, end = "<!-- keys:%s -->" % which, "<!-- /keys:%s -->" % which
        a, b = page.index(start) + len(start), page.index(end)
        page = page[:a] + "\n" + table(which) + "\n" + page[b:]
    return page


def main(argv):
    with open(PAGE, encoding="utf-8") as f:
        page = f.read()
    new = render(page)
    if "--check" in argv:
        if new != page:
            print("docs/mission.md: key tables differ from the schemas; run "
                  "tools/mission_reference.py", file=sys.stderr)  # fmt: skip
            return 1
        return 0
    with open(PAGE, "w", encoding="utf-8") as f:
        f.write(new)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
