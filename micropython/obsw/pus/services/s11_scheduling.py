"""ST[11] time-based scheduling: requests released at their on-board time.

Release times are absolute CUC times (4 coarse, 2 fine octets, the TM time code's epoch)
compared with the application process's ``time()``; shifts are signed CUC durations. The
whole behaviour (insert, delete, shift, reports, sub-schedules, groups, persistence) is the
shared schedule of ``obsw.pus.services.schedule``.
"""

from obsw.pus.fields import field
from obsw.pus.messages import (
    SERVICE_TIME_BASED_SCHEDULING,
    TC_SCHED_CREATE_GROUPS,
    TC_SCHED_DELETE_BY_FILTER,
    TC_SCHED_DELETE_BY_ID,
    TC_SCHED_DELETE_GROUPS,
    TC_SCHED_DETAIL_REPORT_ALL,
    TC_SCHED_DETAIL_REPORT_BY_FILTER,
    TC_SCHED_DETAIL_REPORT_BY_ID,
    TC_SCHED_DISABLE,
    TC_SCHED_DISABLE_GROUPS,
    TC_SCHED_DISABLE_SUBSCHEDULES,
    TC_SCHED_ENABLE,
    TC_SCHED_ENABLE_GROUPS,
    TC_SCHED_ENABLE_SUBSCHEDULES,
    TC_SCHED_INSERT,
    TC_SCHED_REPORT_GROUP_STATUS,
    TC_SCHED_REPORT_SUBSCHEDULE_STATUS,
    TC_SCHED_RESET,
    TC_SCHED_SUMMARY_REPORT_ALL,
    TC_SCHED_SUMMARY_REPORT_BY_FILTER,
    TC_SCHED_SUMMARY_REPORT_BY_ID,
    TC_SCHED_TIME_SHIFT_ALL,
    TC_SCHED_TIME_SHIFT_BY_FILTER,
    TC_SCHED_TIME_SHIFT_BY_ID,
    TM_SCHED_DETAIL_REPORT,
    TM_SCHED_GROUP_STATUS_REPORT,
    TM_SCHED_SUBSCHEDULE_STATUS_REPORT,
    TM_SCHED_SUMMARY_REPORT,
)
from obsw.pus.ptc_time import cuc_pfc
from obsw.pus.services.schedule import Schedule
from obsw.pus.services.schedule_user import ScheduleUser
from obsw.timecode import Cuc

RELEASE_TIME = field(9, cuc_pfc(4, 2))
TIME_OFFSET = field(10, cuc_pfc(4, 2))
_CUC = Cuc(4, 2)
_TICKS = 65536  # fine counts per second


def ticks(seconds):
    """Seconds as an integer count of 1/65536 s (how the schedule holds times)."""
    c, f = _CUC.from_seconds(seconds)
    return (c << 16) | f


class TimeScheduling(Schedule):
    """The service 11 provider; ``margin`` in seconds (see ``Schedule`` for the rest)."""

    SERVICE = SERVICE_TIME_BASED_SCHEDULING
    REPORTS = (
        TM_SCHED_DETAIL_REPORT,
        TM_SCHED_SUMMARY_REPORT,
        TM_SCHED_SUBSCHEDULE_STATUS_REPORT,
        TM_SCHED_GROUP_STATUS_REPORT,
    )
    NAME = "s11"
    TAG = RELEASE_TIME
    OFFSET = TIME_OFFSET
    TAG_MAX = (1 << 48) - 1
    TM_DETAIL = TM_SCHED_DETAIL_REPORT
    TM_SUMMARY = TM_SCHED_SUMMARY_REPORT
    TM_SUBSCHEDULES = TM_SCHED_SUBSCHEDULE_STATUS_REPORT
    TM_GROUPS = TM_SCHED_GROUP_STATUS_REPORT
    HANDLERS = (
        (TC_SCHED_ENABLE, "enable"),
        (TC_SCHED_DISABLE, "disable"),
        (TC_SCHED_RESET, "reset"),
        (TC_SCHED_INSERT, "insert"),
        (TC_SCHED_DELETE_BY_ID, "delete_ids"),
        (TC_SCHED_DELETE_BY_FILTER, "delete_filter"),
        (TC_SCHED_TIME_SHIFT_BY_ID, "shift_ids"),
        (TC_SCHED_TIME_SHIFT_BY_FILTER, "shift_filter"),
        (TC_SCHED_DETAIL_REPORT_BY_ID, "detail_ids"),
        (TC_SCHED_DETAIL_REPORT_BY_FILTER, "detail_filter"),
        (TC_SCHED_SUMMARY_REPORT_BY_ID, "summary_ids"),
        (TC_SCHED_SUMMARY_REPORT_BY_FILTER, "summary_filter"),
        (TC_SCHED_TIME_SHIFT_ALL, "shift_all"),
        (TC_SCHED_DETAIL_REPORT_ALL, "detail_all"),
        (TC_SCHED_SUMMARY_REPORT_ALL, "summary_all"),
        (TC_SCHED_REPORT_SUBSCHEDULE_STATUS, "report_subschedules"),
        (TC_SCHED_ENABLE_SUBSCHEDULES, "enable_subschedules"),
        (TC_SCHED_DISABLE_SUBSCHEDULES, "disable_subschedules"),
        (TC_SCHED_CREATE_GROUPS, "create_groups"),
        (TC_SCHED_DELETE_GROUPS, "delete_groups"),
        (TC_SCHED_ENABLE_GROUPS, "enable_groups"),
        (TC_SCHED_DISABLE_GROUPS, "disable_groups"),
        (TC_SCHED_REPORT_GROUP_STATUS, "report_groups"),
    )

    def __init__(self, margin=0, **options):
        super().__init__(margin=ticks(margin), **options)

    def now(self):
        return ticks(self.app.time())

    def tag_in(self, value):
        return (value[0] << 16) | value[1]

    def tag_out(self, tag):
        return (tag >> 16, tag & 0xFFFF)


class TimeSchedulingUser(ScheduleUser):
    """The service 11 user; release times and offsets are seconds (int or float)."""

    SERVICE = SERVICE_TIME_BASED_SCHEDULING
    TAG = RELEASE_TIME
    OFFSET = TIME_OFFSET
    TAG_NAME = "time"
    TM_DETAIL = TM_SCHED_DETAIL_REPORT
    TM_SUMMARY = TM_SCHED_SUMMARY_REPORT
    TM_SUBSCHEDULES = TM_SCHED_SUBSCHEDULE_STATUS_REPORT
    TM_GROUPS = TM_SCHED_GROUP_STATUS_REPORT
    DECODERS = (
        (TM_SCHED_DETAIL_REPORT, "decode_detail"),
        (TM_SCHED_SUMMARY_REPORT, "decode_summary"),
        (TM_SCHED_SUBSCHEDULE_STATUS_REPORT, "decode_status"),
        (TM_SCHED_GROUP_STATUS_REPORT, "decode_status"),
    )
    TC = {
        "enable": TC_SCHED_ENABLE,
        "disable": TC_SCHED_DISABLE,
        "reset": TC_SCHED_RESET,
        "insert": TC_SCHED_INSERT,
        "delete_ids": TC_SCHED_DELETE_BY_ID,
        "delete_filter": TC_SCHED_DELETE_BY_FILTER,
        "shift_ids": TC_SCHED_TIME_SHIFT_BY_ID,
        "shift_filter": TC_SCHED_TIME_SHIFT_BY_FILTER,
        "shift_all": TC_SCHED_TIME_SHIFT_ALL,
        "detail_ids": TC_SCHED_DETAIL_REPORT_BY_ID,
        "detail_filter": TC_SCHED_DETAIL_REPORT_BY_FILTER,
        "detail_all": TC_SCHED_DETAIL_REPORT_ALL,
        "summary_ids": TC_SCHED_SUMMARY_REPORT_BY_ID,
        "summary_filter": TC_SCHED_SUMMARY_REPORT_BY_FILTER,
        "summary_all": TC_SCHED_SUMMARY_REPORT_ALL,
        "report_subschedules": TC_SCHED_REPORT_SUBSCHEDULE_STATUS,
        "enable_subschedules": TC_SCHED_ENABLE_SUBSCHEDULES,
        "disable_subschedules": TC_SCHED_DISABLE_SUBSCHEDULES,
        "create_groups": TC_SCHED_CREATE_GROUPS,
        "delete_groups": TC_SCHED_DELETE_GROUPS,
        "enable_groups": TC_SCHED_ENABLE_GROUPS,
        "disable_groups": TC_SCHED_DISABLE_GROUPS,
        "report_groups": TC_SCHED_REPORT_GROUP_STATUS,
    }

    def tag_out(self, value):
        return value[0] + value[1] / _TICKS
