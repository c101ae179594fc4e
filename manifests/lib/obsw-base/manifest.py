metadata(
    version="0.1.0",
    description="the package and what every part needs: clocks, CRCs, space packets, time codes",
)

for _m in ("__init__.py", "compat.py", "crc.py", "spp.py", "utc.py", "timecode.py"):
    module("obsw/" + _m, base_path="../../../micropython")
