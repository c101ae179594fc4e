metadata(
    version="0.1.0",
    description="what every part needs: clocks, CRCs, bounded JSON, space packets, time codes",
)

for _m in ("__init__.py", "compat.py", "crc.py", "jsonsafe.py", "spp.py", "utc.py", "timecode.py"):
    module("obsw/" + _m, base_path="../../../micropython")
