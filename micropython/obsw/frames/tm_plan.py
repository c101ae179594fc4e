"""The TM virtual channel plan: which VC carries real-time, playback and essential telemetry.

A plan is a dict of role to VC ID: ``realtime`` (what the applications send now, VC 0 by
default), ``playback`` (packets retrieved from the packet stores by PUS service 15, VC 1)
and ``essential`` (high-priority telemetry, VC 6, the VC the reconfiguration module's HPTM
uses). VC 7 is left to idle frames. The multiplexer serves essential first, then real time,
then playback, so a long playback never delays live telemetry.
"""

from obsw.frames.tm_mux import TmVirtualChannel

REALTIME_VCID = 0
PLAYBACK_VCID = 1
ESSENTIAL_VCID = 6
ROLES = ("realtime", "playback", "essential")
PRIORITIES = {"essential": 3, "realtime": 2, "playback": 1}
_IDLE_VCID = 7


class TmPlanError(ValueError):
    """A plan entry that is not a usable VC ID (unknown role, out of range, used twice)."""

    def __init__(self, role, value, expected):
        super().__init__("TM VC plan %s is %r, expected %s" % (role, value, expected))
        self.role = role
        self.value = value
        self.expected = expected


def tm_plan(config=None):
    """The plan with ``config`` (a dict of role to VC ID, e.g. from the spacecraft database's
    frames section) over the defaults; raises TmPlanError for a bad entry."""
    plan = {"realtime": REALTIME_VCID, "playback": PLAYBACK_VCID, "essential": ESSENTIAL_VCID}
    for role, vcid in (config or {}).items():
        if role not in plan:
            raise TmPlanError(role, vcid, "one of the roles %s" % ", ".join(ROLES))
        plan[role] = vcid
    seen = {}
    for role in ROLES:
        vcid = plan[role]
        if not isinstance(vcid, int) or isinstance(vcid, bool) or not 0 <= vcid < _IDLE_VCID:
            raise TmPlanError(role, vcid, "a VC ID from 0 to 6 (7 carries idle frames)")
        if vcid in seen:
            raise TmPlanError(role, vcid, "a VC ID of its own (%s has it)" % seen[vcid])
        seen[vcid] = role
    return plan


def plan_channels(plan, capacity=16384):
    """The TmVirtualChannels of ``plan`` (from ``tm_plan``), named after their roles."""
    return [TmVirtualChannel(plan[r], PRIORITIES[r], capacity, r) for r in ROLES]
