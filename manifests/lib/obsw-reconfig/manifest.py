metadata(
    version="0.1.0",
    description="the reconfiguration module: CPDU, safeguard memory, time, essential TC/TM",
)

require("obsw-base", library="obsw")
require("obsw-frames", library="obsw")
require("obsw-spacecan-node", library="obsw")
require("obsw-update", library="obsw")

package(
    "obsw/reconfig",
    files=[
        "__init__.py",
        "app.py",
        "appslot.py",
        "cpdu.py",
        "ds3231.py",
        "ecc.py",
        "eeprom.py",
        "essential.py",
        "hal.py",
        "mission.py",
        "node.py",
        "obclink.py",
        "recovery.py",
        "safeguard.py",
        "watchdog.py",
    ],
    base_path="../../../micropython",
)
