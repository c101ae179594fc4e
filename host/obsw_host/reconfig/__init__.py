"""Host side of the reconfiguration module: the simulated module (two MicroPython controller
processes on shared simulated lines, EEPROM and RTC models, ptys, a CAN hub) and the OBC."""

import json
import os


def board_file(ids, folder, recovery=None):
    """Write the mission's ids for the reconfiguration boards (``obsw.reconfig.mission``) as
    ``folder/mission.json``; returns its path. Copy it to each board's flash beside
    ``tc.keys`` (``mpremote cp mission.json :``). ``recovery``: the mission's ``recovery``
    section (the autonomous recovery's thresholds), written with the ids when given."""
    from obsw.reconfig.mission import FILE, parse

    doc = ids.reconfig_board()
    if recovery is not None:
        doc["recovery"] = dict(recovery)
    parse(doc)  # what the board would refuse, refused here
    path = os.path.join(folder, FILE)
    with open(path, "w") as f:
        json.dump(doc, f)
        f.write("\n")
    return path
