"""Start the reconfiguration application on this board (frozen; main.py imports it)."""

from hal_pyb import PybHal
from obsw.reconfig.app import ReconfigApp

hal = PybHal()
app = ReconfigApp(hal)
app.run()
