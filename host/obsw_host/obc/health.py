"""The OBC's own health: CPU load, memory, disk, temperature, uptime, restarts and watchdog.

``HostHealth(root)`` reads Linux's files under ``root`` (``/`` on the OBC, a simulated tree in
tests): ``proc/stat`` (CPU load: the busy share of the jiffies between two samples),
``proc/meminfo`` (``MemAvailable`` of ``MemTotal``), ``proc/uptime``,
``sys/class/thermal/<zone>/temp`` (millidegrees Celsius; on a Raspberry Pi ``thermal_zone0``
is the SoC) and ``statvfs`` of the state folder. A file that cannot be read gives NaN (floats)
or 0, never an exception: the telemetry shows what is known.

``ObcHealth`` is the ``Obc`` component (``obsw_host.obc.topology.OBC_HEALTH``) the PUS process
provides: its attributes are the last sample, published when they change, and the platform
manager's figures (``restarts``, ``watchdog``) that it sends through ``Platform.status``.
"""

import os

NAN = float("nan")
_FIGURES = ("cpu_load", "memory_used", "disk_used", "temperature", "uptime")


class HostHealth:
    """Samples of the machine's health from the files under ``root`` (see the module text)."""

    def __init__(self, root="/", disk="/", thermal_zone="thermal_zone0"):
        self.root = root
        self.disk = disk
        self.thermal_zone = thermal_zone
        self._cpu = None  # (busy, total) jiffies of the last sample

    def _path(self, *parts):
        return os.path.join(self.root, *parts)

    def _read(self, *parts):
        with open(self._path(*parts)) as f:
            return f.read()

    def cpu_load(self):
        """Percent of CPU time busy since the last call (NaN at the first)."""
        try:
            line = self._read("proc", "stat").splitlines()[0].split()
            values = [int(v) for v in line[1:]]
        except (OSError, IndexError, ValueError):
            return NAN
        idle = values[3] + (values[4] if len(values) > 4 else 0)  # idle + iowait
        total = sum(values[:8])  # guest time is already inside user and nice
        last, self._cpu = self._cpu, (total - idle, total)
        if last is None or total <= last[1]:
            return NAN
        return 100.0 * (total - idle - last[0]) / (total - last[1])

    def memory_used(self):
        try:
            info = {}
            for line in self._read("proc", "meminfo").splitlines():
                key, _, rest = line.partition(":")
                info[key] = int(rest.split()[0])
            total = info["MemTotal"]
            available = info.get("MemAvailable", info.get("MemFree", 0))
        except (OSError, KeyError, ValueError, IndexError):
            return NAN
        return 100.0 * (total - available) / total if total else NAN

    def disk_used(self):
        try:
            st = os.statvfs(self.disk)
        except OSError:
            return NAN
        if not st.f_blocks:
            return NAN
        return 100.0 * (st.f_blocks - st.f_bfree) / st.f_blocks

    def temperature(self):
        try:
            return int(self._read("sys", "class", "thermal", self.thermal_zone, "temp")) / 1000.0
        except (OSError, ValueError):
            return NAN

    def uptime(self):
        try:
            return int(float(self._read("proc", "uptime").split()[0]))
        except (OSError, ValueError, IndexError):
            return 0

    def sample(self):
        """Every figure now, by attribute name."""
        return {name: getattr(self, name)() for name in _FIGURES}


def _same(a, b):
    return a == b or (a != a and b != b)  # NaN equals NaN here: no publication for it


class ObcHealth:
    """The ``Obc`` component: the last sample of ``host`` and the platform manager's figures."""

    def __init__(self, host):
        self.host = host
        self.values = dict.fromkeys(_FIGURES, NAN)
        self.values["uptime"] = 0
        self.values["restarts"] = 0
        self.values["watchdog"] = 0
        self.provider = None

    def il_bind(self, provider):
        self.provider = provider

    def __getattr__(self, name):
        values = self.__dict__.get("values")
        if values is not None and name in values:
            return values[name]
        raise AttributeError(name)

    def _update(self, name, value):
        if not _same(self.values[name], value):
            self.values[name] = value
            if self.provider is not None:
                self.provider.node.publish("Obc", name, value)

    def sample(self):
        """Read the machine's figures now and publish those that changed."""
        for name, value in self.host.sample().items():
            self._update(name, value)

    def status(self, restarts, watchdog):
        """The platform manager's figures (``Platform.status``)."""
        self._update("restarts", int(restarts))
        self._update("watchdog", int(watchdog))
