"""The checks of a day in the life, shared by both rigs (``obsw_sim.ditl``, one process on one
injected clock, and ``obsw_sim.ditl_chain``, the whole chain under libfaketime).

``checks(f, full)`` takes the figures both rigs give in one form:

- ``hours``, ``orbits``, ``passes`` (passes flown);
- ``hk_due`` (housekeeping reports that had to come), ``missing``, ``duplicates``,
  ``resends`` (the ground's requests to send again);
- ``planned``, ``executed``, ``max_lateness`` (s, onboard time);
- ``files``: ``{"down"|"up": {"size", "identical", "transactions" (None: not counted),
  "progress" (the receiver's octets at each AOS)}}``;
- ``overflow`` (true if a store overflowed or the passes could not carry what was generated)
  and ``store_detail`` (the figures behind it);

and returns ``(name, ok, detail)`` for each check. ``utc(t)`` writes POSIX time ``t``;
``page(..)`` is the Markdown of the last run's page, laid out alike for both rigs.
"""

import datetime

from obsw_host.ops.tle import format_time


def utc(t):
    return format_time(datetime.datetime.fromtimestamp(t, datetime.timezone.utc))


def checks(f, full):
    """(name, ok, detail) of each check of the run (see the module text)."""
    out = []
    if full:
        out.append(("24 hours, 15 orbits, 4 passes", f["hours"] >= 24 and f["orbits"] >= 15
                    and f["passes"] >= 4, "%.1f h, %.1f orbits, %d passes" % (
                        f["hours"], f["orbits"], f["passes"])))  # fmt: skip
    else:
        out.append(("two orbits, two passes", f["orbits"] >= 2 and f["passes"] >= 2,
                    "%.1f orbits, %d passes" % (f["orbits"], f["passes"])))  # fmt: skip
    out.append(("housekeeping delivered exactly once", f["missing"] == 0 and
                f["duplicates"] == 0 and f["hk_due"] > 0, "%d due, %d missing, %d duplicates, "
                "%d asked again" % (f["hk_due"], f["missing"], f["duplicates"],
                                    f["resends"])))  # fmt: skip
    out.append(("planned commands executed within 1 s", f["executed"] == f["planned"] > 0
                and f["max_lateness"] <= 1.0, "%d of %d, at most %.3f s from its time" % (
                    f["executed"], f["planned"], f["max_lateness"])))  # fmt: skip
    for name in ("down", "up"):
        d = f["files"][name]
        prog = d["progress"]
        across = any(0 < p < d["size"] for p in prog)  # a pass began with the file part-way
        once = d["transactions"] in (None, 1)
        ok = d["identical"] and across and once and prog == sorted(prog)
        detail = "identical %s; received at each AOS %s" % (d["identical"], prog)
        if d["transactions"] is not None:
            detail += "; %d transaction(s)" % d["transactions"]
        out.append(("%s file (%d octets) identical across passes, never restarted" % (
            name, d["size"]), ok, detail))  # fmt: skip
    out.append(("stores never overflow", not f["overflow"], f["store_detail"]))
    return out


def _table(head, rows):
    return ["| %s |" % " | ".join(head), "|%s" % ("---|" * len(head))] + [
        "| %s |" % " | ".join(str(c) for c in r) for r in rows
    ]


def page(intro, plot_alt, results, passes, pass_use, sent_head, plan_rows, executed_head,
         files=None):  # fmt: skip
    """The last run's page: ``intro`` (a paragraph), the plots (``plot_alt``), the checks
    (``results``), the files (``files``: lines, or None), the passes (``pass_use``: ``(aos,
    los, sent, volume)`` of each of ``passes``, ``sent`` headed ``sent_head``) and the commands
    (``plan_rows``: ``(planned, executed, request)``, the executed column headed
    ``executed_head``)."""
    checks_md = _table(["check", "result", "figures"],
                       [(n, "pass" if ok else "FAIL", d) for n, ok, d in results])  # fmt: skip
    pass_md = _table(["pass", "AOS (UTC)", "LOS (UTC)", "max el", "volume (octets)", sent_head],
                     [(i + 1, utc(p.aos), utc(p.los), "%.1f" % p.max_elevation, int(u[3]),
                       int(u[2])) for i, (p, u) in enumerate(zip(passes, pass_use))])  # fmt: skip
    plan_md = _table(["planned (UTC)", executed_head, "request"], plan_rows)
    out = ["# Day in the life: the last run", "", intro, "",
           "![%s](ditl.png)" % plot_alt, "", "## Checks", "", *checks_md, ""]  # fmt: skip
    if files is not None:
        out += ["## Files", "", *files, ""]
    out += ["## Passes", "", *pass_md, "", "## Commands planned and executed", "", *plan_md, ""]
    return "\n".join(out)
