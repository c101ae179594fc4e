"""Start the reconfiguration application on this board (frozen; main.py imports it).

The boot selector (``obsw.reconfig.appslot``) runs an updated application from the flash's
``app/`` when its record says so, else, or when it fails, this image's frozen one."""

from obsw.reconfig import appslot

ROOT = "/flash"


def start():
    from hal_pyb import PybHal
    from obsw.reconfig import mission
    from obsw.reconfig.app import ReconfigApp
    from obsw.reconfig.essential import security_from_file

    hal = PybHal()
    # the mission's SCID, node ids, essential MAP and HPTM VC from mission.json on the flash
    ids = mission.load()
    if ids is None:
        print("no mission.json on the board: the reconfiguration module's built-in ids")
        ids = {}
    # TC frames are authenticated with the SDLS key file on the board's flash; without one
    # every essential TC is refused, unless the mission chose unauthenticated commanding
    app = ReconfigApp(hal, essential_security=security_from_file("tc.keys", "tc.insecure"), **ids)
    app.on_healthy = lambda: appslot.confirm(ROOT)  # an updated application is kept
    app.run()


appslot.boot(ROOT, start)
