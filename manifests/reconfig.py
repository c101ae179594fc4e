# The reconfiguration module's image: its application and only the core modules it imports.
# Every module that the entry point (boards/OBSW_RECONFIG/reconfig_main.py) imports, directly or
# not, must be listed: tests/host/test_manifests.py and the firmware stage check it
# (`tools/mpy.py closure manifests/reconfig.py boards/OBSW_RECONFIG/reconfig_main.py`).
metadata(
    version="0.1.0",
    description="obsw reconfiguration module (CPDU, safeguard memory, time, essential TC/TM)",
)

_CORE = "../micropython"

for _m in (
    "__init__.py",
    "compat.py",
    "crc.py",
    "spp.py",
    "utc.py",
    "timecode.py",
):
    module("obsw/" + _m, base_path=_CORE)

package(
    "obsw/spacecan",
    files=[
        "__init__.py",
        "encoding.py",
        "events.py",
        "fragment.py",
        "ids.py",
        "nodedef.py",
        "packets.py",
        "redundancy.py",
        "responder.py",
        "timeframes.py",
    ],
    base_path=_CORE,
)
package(
    "obsw/frames",
    files=[
        "__init__.py",
        "asm.py",
        "bch.py",
        "clcw.py",
        "cltu.py",
        "dedup.py",
        "errors.py",
        "farm.py",
        "processor.py",
        "randomizer.py",
        "aes.py",
        "gcm.py",
        "sdls.py",
        "sdls_gcm.py",
        "sdls_keys.py",
        "sdls_mac.py",
        "tc.py",
        "tm.py",
        "tm_mux.py",
        "tm_plan.py",
    ],
    base_path=_CORE,
)
package(
    "obsw/reconfig",
    files=[
        "__init__.py",
        "app.py",
        "cpdu.py",
        "ds3231.py",
        "ecc.py",
        "eeprom.py",
        "essential.py",
        "hal.py",
        "node.py",
        "safeguard.py",
        "watchdog.py",
    ],
    base_path=_CORE,
)
# the Pyboard hardware layer
module("hal_pyb.py", base_path="../boards/common")
module("reconfig_main.py", base_path="../boards/OBSW_RECONFIG")
