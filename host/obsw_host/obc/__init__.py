"""The onboard computer assembled from one mission configuration file.

``config`` reads the file, ``units`` builds each component from its section, ``assembly``
runs the components of one process with its heartbeat, ``platform`` starts and watches the
processes. ``obsw obc serve [MISSION]`` runs it all, after ``obsw_host.mission`` has checked the
whole mission folder (the sample spacecraft is ``examples/sample``).
"""
