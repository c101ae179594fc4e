"""The systemd unit of the OBC: ``obsw obc serve`` of one mission, supervised by systemd.

``unit_text(...)`` renders the unit that ``obsw obc install-service`` writes (and that
``boards/raspberry-pi/obsw.service`` ships for the default paths). ``Type=notify`` with
``WatchdogSec=``: the platform manager says ``READY=1`` when every process is up and sends
``WATCHDOG=1`` from its loop (``obsw_host.obc.supervision``); a platform manager that hangs
is killed with SIGABRT and started again (``Restart=on-failure``).
"""

import os

UNIT_NAME = "obsw.service"
UNIT_DIR = "/etc/systemd/system"
DEFAULTS = {
    "mission": "/etc/obsw/mission.json",
    "obsw": "/opt/obsw/bin/obsw",
    "state": "/var/lib/obsw",
    "user": "obsw",
    "watchdog_sec": 10,
}

_TEMPLATE = """\
# {unit_dir}/{unit_name}: the onboard computer (docs/raspberry-pi.md, docs/supervision.md)
# Written by `obsw obc install-service`; systemd supervises the platform manager, which
# supervises the OBC's processes and feeds the hardware watchdog.
[Unit]
Description=obsw onboard computer ({mission})
Wants=network.target sys-subsystem-net-devices-can0.device sys-subsystem-net-devices-can1.device
After=network.target sys-subsystem-net-devices-can0.device sys-subsystem-net-devices-can1.device
StartLimitIntervalSec=300
StartLimitBurst=10

[Service]
Type=notify
NotifyAccess=main
User={user}
Group={user}
SupplementaryGroups=dialout
ExecStart={obsw} obc serve {mission} --state {state}
WatchdogSec={watchdog_sec}
Restart=on-failure
RestartSec=2
TimeoutStartSec=120
KillMode=control-group
TimeoutStopSec=15

[Install]
WantedBy=multi-user.target
"""


def unit_text(**options):
    """The unit for ``options`` (keys of ``DEFAULTS``; the missing ones take those)."""
    values = dict(DEFAULTS)
    unknown = set(options) - set(values)
    if unknown:
        raise TypeError("no unit option %s" % ", ".join(sorted(unknown)))
    values.update((k, v) for k, v in options.items() if v is not None)
    for key in ("mission", "obsw", "state"):
        if any(ch.isspace() for ch in str(values[key])):
            raise ValueError("%s path %r has white space: systemd would split it" % (
                key, values[key]))  # fmt: skip
    if int(values["watchdog_sec"]) < 1:
        raise ValueError("watchdog_sec must be at least 1 s, got %r" % values["watchdog_sec"])
    return _TEMPLATE.format(unit_dir=UNIT_DIR, unit_name=UNIT_NAME, **values)


def install(text, root="/"):
    """Write ``text`` as the unit under ``root`` (atomically); returns its path."""
    folder = os.path.join(root, UNIT_DIR.lstrip("/"))
    os.makedirs(folder, exist_ok=True)
    path = os.path.join(folder, UNIT_NAME)
    tmp = path + ".new"
    with open(tmp, "w") as f:
        f.write(text)
        f.flush()
        os.fsync(f.fileno())
    os.chmod(tmp, 0o644)
    os.replace(tmp, path)
    return path
