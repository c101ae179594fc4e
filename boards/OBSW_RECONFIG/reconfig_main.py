"""Start the reconfiguration application on this board (frozen; main.py imports it)."""

from hal_pyb import PybHal
from obsw.reconfig.app import ReconfigApp
from obsw.reconfig.essential import security_from_file

hal = PybHal()
# TC frames are authenticated with the SDLS key file on the board's flash; without one every
# essential TC is refused, unless the mission chose unauthenticated commanding (tc.insecure)
app = ReconfigApp(hal, essential_security=security_from_file("tc.keys", "tc.insecure"))
app.run()
