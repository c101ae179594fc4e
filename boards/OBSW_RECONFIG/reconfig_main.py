"""Start the reconfiguration application on this board (frozen; main.py imports it)."""

from hal_pyb import PybHal
from obsw.reconfig.app import ReconfigApp
from obsw.reconfig.essential import security_from_file
from obsw.reconfig.recovery import settings_from_file

hal = PybHal()
# TC frames are authenticated with the SDLS key file on the board's flash, when there is one
# the mission's recovery thresholds (`obsw board deploy` copies recovery.json), else the defaults
app = ReconfigApp(
    hal,
    essential_security=security_from_file("tc.keys"),
    recovery=settings_from_file("recovery.json"),
)
app.run()
