metadata(
    version="0.1.0",
    description="what every part needs: clocks, CRCs, errors, bounded JSON, packets, time codes",
)

_MODULES = ("__init__", "compat", "crc", "errors", "jsonsafe", "spp", "utc", "timecode")
for _m in _MODULES:
    module("obsw/%s.py" % _m, base_path="../../../micropython")
