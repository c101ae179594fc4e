"""ST[22] position-based scheduling: requests released when a position is reached.

The position is a parameter of the pool (e.g. the distance a rover has travelled, which its
navigation component publishes); an activity is released once the position reaches its tag.
Tags are unsigned 32-bit integers in the parameter's unit and shifts signed 32-bit ones
(both mission choices, ``POSITION`` and ``POSITION_OFFSET``). Everything else is the
schedule shared with service 11 (``obsw.pus.services.schedule``). The orbit-number request
TC[22,28] has no meaning for a rover and is not served.
"""

from obsw.pus.fields import field
from obsw.pus.messages import (
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
    TC_POS_SCHED_SUMMARY_REPORT_ALL,
    TC_POS_SCHED_SUMMARY_REPORT_BY_FILTER,
    TC_POS_SCHED_SUMMARY_REPORT_BY_ID,
    TM_POS_SCHED_DETAIL_REPORT,
    TM_POS_SCHED_GROUP_STATUS_REPORT,
    TM_POS_SCHED_SUBSCHEDULE_STATUS_REPORT,
    TM_POS_SCHED_SUMMARY_REPORT,
)
from obsw.pus.services.schedule import Schedule
from obsw.pus.services.schedule_user import ScheduleUser

POSITION = field(3, 14)
POSITION_OFFSET = field(4, 14)


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
