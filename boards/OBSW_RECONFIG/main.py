# main.py: start the reconfiguration module. Hold USR while resetting to get the REPL instead.
import pyb

if pyb.Switch()():
    print("USR held: reconfiguration application not started")
else:
    import reconfig_main  # noqa: F401
