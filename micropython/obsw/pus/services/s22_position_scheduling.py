"""ST[22] position-based scheduling: requests released when a position is reached.

The position is a parameter of the pool (e.g. the distance a rover has travelled, which its
navigation component publishes); an activity is released once the position reaches its tag.
Tags are unsigned 32-bit integers in the parameter's unit and shifts signed 32-bit ones
(both mission choices, ``POSITION`` and ``POSITION_OFFSET``). Everything else is the
schedule shared with service 11 (``obsw.pus.services.schedule``).

TC[22,28] sets the orbit number: the position parameter is set to it (through its component,
so the component stays its owner), for a mission whose position is the orbit count (or a
rover's odometer being re-based). The parameter must be writable and the value fit its type,
else the request fails to start with ``FAILURE_REFUSED`` (the parameter ID in the data); a
component that cannot be reached fails its completion as TC[20,3] does. Activities whose tag
the new position has reached are released on the next cycle, as when the position moves.
"""

from obsw.il.errors import CallTimeoutError, InteractionError, UnavailableError
from obsw.pus.fields import field
from obsw.pus.messages import (
    FAILURE_COMPONENT,
    FAILURE_REFUSED,
    FAILURE_TIMEOUT,
    FAILURE_UNAVAILABLE,
    SERVICE_POSITION_BASED_SCHEDULING,
    TC_POS_SCHED_CREATE_GROUPS,
    TC_POS_SCHED_DELETE_BY_FILTER,
    TC_POS_SCHED_DELETE_BY_ID,
    TC_POS_SCHED_DELETE_GROUPS,
    TC_POS_SCHED_DETAIL_REPORT_ALL,
    TC_POS_SCHED_DETAIL_REPORT_BY_FILTER,
    TC_POS_SCHED_DETAIL_REPORT_BY_ID,
    TC_POS_SCHED_DISABLE,
    TC_POS_SCHED_DISABLE_GROUPS,
    TC_POS_SCHED_DISABLE_SUBSCHEDULES,
    TC_POS_SCHED_ENABLE,
    TC_POS_SCHED_ENABLE_GROUPS,
    TC_POS_SCHED_ENABLE_SUBSCHEDULES,
    TC_POS_SCHED_INSERT,
    TC_POS_SCHED_POSITION_SHIFT_ALL,
    TC_POS_SCHED_POSITION_SHIFT_BY_FILTER,
    TC_POS_SCHED_POSITION_SHIFT_BY_ID,
    TC_POS_SCHED_REPORT_GROUP_STATUS,
    TC_POS_SCHED_REPORT_SUBSCHEDULE_STATUS,
    TC_POS_SCHED_RESET,
    TC_POS_SCHED_SET_ORBIT_NUMBER,
    TC_POS_SCHED_SUMMARY_REPORT_ALL,
    TC_POS_SCHED_SUMMARY_REPORT_BY_FILTER,
    TC_POS_SCHED_SUMMARY_REPORT_BY_ID,
    TM_POS_SCHED_DETAIL_REPORT,
    TM_POS_SCHED_GROUP_STATUS_REPORT,
    TM_POS_SCHED_SUBSCHEDULE_STATUS_REPORT,
    TM_POS_SCHED_SUMMARY_REPORT,
)
from obsw.pus.parameters import ParameterError
from obsw.pus.services.base import PARAMETER_ID
from obsw.pus.services.s01_verification import PusFailure
from obsw.pus.services.schedule import Schedule
from obsw.pus.services.schedule_user import ScheduleUser
from obsw.pus.structure import Structure

POSITION = field(3, 14)
POSITION_OFFSET = field(4, 14)
ORBIT = Structure([("orbit", POSITION)])


class PositionScheduling(Schedule):
    """The service 22 provider on ``pool``; ``parameter`` (ID or name) is the position."""

    SERVICE = SERVICE_POSITION_BASED_SCHEDULING
    REPORTS = (
        TM_POS_SCHED_DETAIL_REPORT,
        TM_POS_SCHED_SUMMARY_REPORT,
        TM_POS_SCHED_SUBSCHEDULE_STATUS_REPORT,
        TM_POS_SCHED_GROUP_STATUS_REPORT,
    )
    NAME = "s22"
    TAG = POSITION
    OFFSET = POSITION_OFFSET
    TAG_MAX = 0xFFFFFFFF
    TM_DETAIL = TM_POS_SCHED_DETAIL_REPORT
    TM_SUMMARY = TM_POS_SCHED_SUMMARY_REPORT
    TM_SUBSCHEDULES = TM_POS_SCHED_SUBSCHEDULE_STATUS_REPORT
    TM_GROUPS = TM_POS_SCHED_GROUP_STATUS_REPORT
    HANDLERS = (
        (TC_POS_SCHED_ENABLE, "enable"),
        (TC_POS_SCHED_DISABLE, "disable"),
        (TC_POS_SCHED_RESET, "reset"),
        (TC_POS_SCHED_INSERT, "insert"),
        (TC_POS_SCHED_DELETE_BY_ID, "delete_ids"),
        (TC_POS_SCHED_DELETE_BY_FILTER, "delete_filter"),
        (TC_POS_SCHED_POSITION_SHIFT_BY_ID, "shift_ids"),
        (TC_POS_SCHED_POSITION_SHIFT_BY_FILTER, "shift_filter"),
        (TC_POS_SCHED_DETAIL_REPORT_BY_ID, "detail_ids"),
        (TC_POS_SCHED_DETAIL_REPORT_BY_FILTER, "detail_filter"),
        (TC_POS_SCHED_SUMMARY_REPORT_BY_ID, "summary_ids"),
        (TC_POS_SCHED_SUMMARY_REPORT_BY_FILTER, "summary_filter"),
        (TC_POS_SCHED_POSITION_SHIFT_ALL, "shift_all"),
        (TC_POS_SCHED_DETAIL_REPORT_ALL, "detail_all"),
        (TC_POS_SCHED_SUMMARY_REPORT_ALL, "summary_all"),
        (TC_POS_SCHED_REPORT_SUBSCHEDULE_STATUS, "report_subschedules"),
        (TC_POS_SCHED_ENABLE_SUBSCHEDULES, "enable_subschedules"),
        (TC_POS_SCHED_DISABLE_SUBSCHEDULES, "disable_subschedules"),
        (TC_POS_SCHED_CREATE_GROUPS, "create_groups"),
        (TC_POS_SCHED_DELETE_GROUPS, "delete_groups"),
        (TC_POS_SCHED_ENABLE_GROUPS, "enable_groups"),
        (TC_POS_SCHED_DISABLE_GROUPS, "disable_groups"),
        (TC_POS_SCHED_REPORT_GROUP_STATUS, "report_groups"),
        (TC_POS_SCHED_SET_ORBIT_NUMBER, "set_orbit"),
    )

    def __init__(self, pool, parameter, **options):
        super().__init__(**options)
        self.pool = pool
        self.parameter = pool.sdb.parameter(parameter).id

    def now(self):
        try:
            return self.pool.get(self.parameter)
        except KeyError:
            return None

    def set_orbit(self, req):
        orbit = req.decode(ORBIT)["orbit"]
        pid = self.parameter
        try:
            p = self.pool.parameter(pid)
            if not p.writable:
                raise ParameterError("%s is read-only" % p.qualified, pid)
            p.type.check(orbit)
        except (ParameterError, ValueError) as e:
            raise PusFailure(FAILURE_REFUSED, str(e), PARAMETER_ID.pack(pid)) from None
        req.start()
        if p.component is None or self.pool.node is None:
            self.pool.set(pid, orbit)  # a process-local parameter: nothing to wait for
            return None
        return self._set_remote(pid, orbit)

    async def _set_remote(self, pid, orbit):
        try:
            await self.pool.aset(pid, orbit)
        except (InteractionError, ValueError) as e:
            data = PARAMETER_ID.pack(pid)
            if isinstance(e, CallTimeoutError):
                raise PusFailure(FAILURE_TIMEOUT, e.message, data) from None
            if isinstance(e, UnavailableError):
                raise PusFailure(FAILURE_UNAVAILABLE, e.message, data) from None
            raise PusFailure(FAILURE_COMPONENT, str(e), data) from None


class PositionSchedulingUser(ScheduleUser):
    """The service 22 user; positions and offsets are integers in the parameter's unit."""

    SERVICE = SERVICE_POSITION_BASED_SCHEDULING
    TAG = POSITION
    OFFSET = POSITION_OFFSET
    TAG_NAME = "position"
    TM_DETAIL = TM_POS_SCHED_DETAIL_REPORT
    TM_SUMMARY = TM_POS_SCHED_SUMMARY_REPORT
    TM_SUBSCHEDULES = TM_POS_SCHED_SUBSCHEDULE_STATUS_REPORT
    TM_GROUPS = TM_POS_SCHED_GROUP_STATUS_REPORT
    DECODERS = (
        (TM_POS_SCHED_DETAIL_REPORT, "decode_detail"),
        (TM_POS_SCHED_SUMMARY_REPORT, "decode_summary"),
        (TM_POS_SCHED_SUBSCHEDULE_STATUS_REPORT, "decode_status"),
        (TM_POS_SCHED_GROUP_STATUS_REPORT, "decode_status"),
    )
    TC = {
        "enable": TC_POS_SCHED_ENABLE,
        "disable": TC_POS_SCHED_DISABLE,
        "reset": TC_POS_SCHED_RESET,
        "insert": TC_POS_SCHED_INSERT,
        "delete_ids": TC_POS_SCHED_DELETE_BY_ID,
        "delete_filter": TC_POS_SCHED_DELETE_BY_FILTER,
        "shift_ids": TC_POS_SCHED_POSITION_SHIFT_BY_ID,
        "shift_filter": TC_POS_SCHED_POSITION_SHIFT_BY_FILTER,
        "shift_all": TC_POS_SCHED_POSITION_SHIFT_ALL,
        "detail_ids": TC_POS_SCHED_DETAIL_REPORT_BY_ID,
        "detail_filter": TC_POS_SCHED_DETAIL_REPORT_BY_FILTER,
        "detail_all": TC_POS_SCHED_DETAIL_REPORT_ALL,
        "summary_ids": TC_POS_SCHED_SUMMARY_REPORT_BY_ID,
        "summary_filter": TC_POS_SCHED_SUMMARY_REPORT_BY_FILTER,
        "summary_all": TC_POS_SCHED_SUMMARY_REPORT_ALL,
        "report_subschedules": TC_POS_SCHED_REPORT_SUBSCHEDULE_STATUS,
        "enable_subschedules": TC_POS_SCHED_ENABLE_SUBSCHEDULES,
        "disable_subschedules": TC_POS_SCHED_DISABLE_SUBSCHEDULES,
        "create_groups": TC_POS_SCHED_CREATE_GROUPS,
        "delete_groups": TC_POS_SCHED_DELETE_GROUPS,
        "enable_groups": TC_POS_SCHED_ENABLE_GROUPS,
        "disable_groups": TC_POS_SCHED_DISABLE_GROUPS,
        "report_groups": TC_POS_SCHED_REPORT_GROUP_STATUS,
    }

    def set_orbit(self, apid, orbit):
        """TC[22,28]: set the orbit number (the position parameter) to ``orbit``."""
        return self.request(apid, TC_POS_SCHED_SET_ORBIT_NUMBER, ORBIT.pack({"orbit": orbit}))
