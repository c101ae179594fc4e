"""The onboard computer assembled from one mission configuration file.

``config`` reads the file (``defaults`` holds every default of its sections); ``topology`` is
the composition root everyone reads: the processes, the units each runs (kinds from the
``registry`` table), the mission's plug-in components (``plugins``) and the interfaces that
join them; ``units`` holds the units, ``assembly`` runs the units of one process with its
heartbeat, ``platform`` starts and watches the processes; ``supervision`` watches the
platform manager (the hardware ``watchdog``, systemd through ``sdnotify``, the unit file in
``service``); ``health`` is the OBC's health component and ``monitoring`` the mission's
initial limit checks; ``state`` is the state folder and its lock. ``obsw obc serve [MISSION]``
runs it all, once ``obsw_host.mission`` has checked the whole mission folder (the sample
spacecraft is ``examples/sample``).
"""
