"""The on-board PUS process with the OBCP engine and service 18 (``obsw obcp serve``)."""

import time


def onboard_with_obcp(sdb, *, files=None, level=2, components=None, **options):
    """An ``Onboard`` with the solar panel (unless ``components`` are given), the OBCP engine
    and the service 18 provider (``files`` is the filestore folder for loads by reference).
    Returns ``(onboard, engine)``; the caller starts and stops the onboard."""
    from obsw.cfdp.filestore import OsFilestore
    from obsw.pluto.engine import provide
    from obsw.pus.services.s18_obcp import ObcpManagement

    from obsw_host.pus.onboard import Onboard
    from obsw_host.solar_panel import SOLAR_PANEL, SolarPanel

    if components is None:
        components = [(SOLAR_PANEL, SolarPanel())]
    onboard = Onboard(sdb, components=components, **options)
    engine = provide(
        onboard.node,
        sdb,
        [itf for itf, _ in components],
        timeout=2.0,
        activity_timeout=30.0,
        poll=0.1,
    )
    onboard.app.register(
        ObcpManagement(
            engine,
            filestore=OsFilestore(files) if files else None,
            events=sdb.event,
            level=level,
            clock=time.time,
        )
    )
    return onboard, engine
