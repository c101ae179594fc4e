"""The layout of every TM report the OBC's services send, for the XTCE generator.

``report_layouts(types)`` maps each (service, subtype) to ``(name, layout)``: the very
``Structure`` (or service 12 ``Items``) the OBC's service packs the report with, built as the
PUS process builds it; ``types(pid)`` gives a parameter's field type, as the OBC's parameter
pool does. Reports the generator writes by hand are
left out: verification (service 1, its failure data by code), housekeeping and diagnostic
reports (by structure ID), events (by event ID), the time reports (service 9) and the test
reports (service 17). ``HAND_WRITTEN`` names them, so that a test can check that every type
in the OBC's service tables is one or the other.
"""

from obsw.pus import messages as M
from obsw.pus.services import report_types as fwd
from obsw.pus.services import s02_device_access as s02
from obsw.pus.services import s03_layouts as s03
from obsw.pus.services import s04_statistics as s04
from obsw.pus.services import s05_events as s05
from obsw.pus.services import s06_layouts as s06
from obsw.pus.services import s12_layouts as s12
from obsw.pus.services import s13_large_packets as s13
from obsw.pus.services import s15_layouts as s15
from obsw.pus.services import s18_layouts as s18
from obsw.pus.services import s19_event_action as s19
from obsw.pus.services import s20_parameters as s20
from obsw.pus.services import s21_sequencing as s21
from obsw.pus.services import s23_layouts as s23
from obsw.pus.services import schedule_layouts as sched
from obsw.pus.services.s11_scheduling import TimeScheduling
from obsw.pus.services.s22_position_scheduling import PositionScheduling

HAND_WRITTEN = (
    M.TM_VERIFY_ACCEPTANCE_SUCCESS,
    M.TM_VERIFY_ACCEPTANCE_FAILURE,
    M.TM_VERIFY_START_SUCCESS,
    M.TM_VERIFY_START_FAILURE,
    M.TM_VERIFY_PROGRESS_SUCCESS,
    M.TM_VERIFY_PROGRESS_FAILURE,
    M.TM_VERIFY_COMPLETION_SUCCESS,
    M.TM_VERIFY_COMPLETION_FAILURE,
    M.TM_VERIFY_ROUTING_FAILURE,
    M.TM_HK_HK_REPORT,
    M.TM_HK_DIAG_REPORT,
    M.TM_EVENT_INFORMATIVE,
    M.TM_EVENT_LOW_SEVERITY,
    M.TM_EVENT_MEDIUM_SEVERITY,
    M.TM_EVENT_HIGH_SEVERITY,
    M.TM_TIME_CUC_REPORT,
    M.TM_TIME_CDS_REPORT,
    M.TM_TEST_ARE_YOU_ALIVE_REPORT,
    M.TM_TEST_ON_BOARD_CONNECTION_REPORT,
)


def report_layouts(types):
    """{(service, subtype): (name, layout)} of the reports above (see the module text)."""
    monitoring = s12.Layouts(types)
    fmon = s12.fmon_layouts()
    timed = sched.Layouts(TimeScheduling.TAG, TimeScheduling.OFFSET)
    placed = sched.Layouts(PositionScheduling.TAG, PositionScheduling.OFFSET)
    table = (
        (M.TM_DEVICE_REGISTER_DUMP_REPORT, "register_dump", s02.REGISTERS),
        (M.TM_DEVICE_PHYSICAL_DATA_REPORT, "physical_device_data", s02.PHYSICAL),
        (M.TM_DEVICE_LOGICAL_DATA_REPORT, "logical_device_data", s02.LOGICAL),
        (M.TM_HK_HK_STRUCTURE_REPORT, "hk_structure_report", s03.STRUCTURE_REPORT),
        (M.TM_HK_DIAG_STRUCTURE_REPORT, "diag_structure_report", s03.STRUCTURE_REPORT),
        (M.TM_HK_HK_PERIODIC_PROPERTIES_REPORT, "hk_properties", s03.PROPERTIES_REPORT),
        (M.TM_HK_DIAG_PERIODIC_PROPERTIES_REPORT, "diag_properties_report", s03.PROPERTIES_REPORT),
        (
            M.TM_HK_FUNCTIONAL_REPORTING_REPORT,
            "functional_reporting_report",
            s03.FUNCTIONAL_REPORT,
        ),
        (M.TM_STATS_REPORT, "statistics", s04.report_layout(types)),
        (M.TM_STATS_DEFINITIONS_REPORT, "statistics_definitions", s04.DEFINITIONS_REPORT),
        (M.TM_EVENT_DISABLED_LIST_REPORT, "disabled_events", s05.IDS),
        (M.TM_MEM_DUMP_OBJECT_REPORT, "memory_object_dump", s06.OBJECT_DUMP_REPORT),
        (M.TM_MEM_DUMP_RAW_REPORT, "raw_memory_dump", s06.DUMP_REPORT),
        (M.TM_MEM_CHECK_OBJECT_REPORT, "memory_object_check", s06.OBJECT_CHECK_REPORT),
        (M.TM_MEM_CHECK_RAW_REPORT, "raw_memory_check", s06.CHECK_REPORT),
        (
            M.TM_MEM_CHECK_OBJECT_WHOLE_REPORT,
            "memory_whole_object_report",
            s06.OBJECT_WHOLE_REPORT,
        ),
        (M.TM_SCHED_DETAIL_REPORT, "schedule_detail", timed.activities),
        (M.TM_SCHED_SUMMARY_REPORT, "schedule_summary", timed.summary),
        (M.TM_SCHED_SUBSCHEDULE_STATUS_REPORT, "subschedule_status", sched.STATUS_REPORT),
        (M.TM_SCHED_GROUP_STATUS_REPORT, "schedule_group_status", sched.STATUS_REPORT),
        (M.TM_MON_PARAMETER_MONITORING_REPORT, "monitoring_definitions", monitoring.report),
        (M.TM_MON_OUT_OF_LIMITS_REPORT, "out_of_limits", monitoring.transitions),
        (M.TM_MON_CHECK_TRANSITION_REPORT, "check_transition", monitoring.transitions),
        (M.TM_MON_PARAMETER_MONITORING_STATUS_REPORT, "monitoring_status", s12.STATUS_REPORT),
        (M.TM_MON_FUNCTIONAL_MONITORING_REPORT, "functional_definition_report", fmon.report),
        (M.TM_MON_FUNCTIONAL_MONITORING_STATUS_REPORT, "functional_status_report", fmon.status),
        (M.TM_LARGE_DOWNLINK_FIRST, "large_downlink_first", s13.PART),
        (M.TM_LARGE_DOWNLINK_INTERMEDIATE, "large_downlink_part", s13.PART),
        (M.TM_LARGE_DOWNLINK_LAST, "large_downlink_last", s13.PART),
        (M.TM_LARGE_UPLINK_ABORTION, "large_uplink_abortion", s13.ABORTION),
        (M.TM_FWD_REPORT_TYPES_REPORT, "forwarded_types", fwd.REPORT_TYPES),
        (M.TM_FWD_HK_STRUCTURES_REPORT, "forwarded_hk", fwd.HK_IDS),
        (M.TM_FWD_DIAG_STRUCTURES_REPORT, "forward_diag_report", fwd.HK_IDS),
        (M.TM_FWD_BLOCKED_EVENTS_REPORT, "blocked_events", fwd.EVENT_IDS),
        (M.TM_STORE_REPORT_TYPES_REPORT, "stored_types", s15.STORE_TYPES),
        (M.TM_STORE_CONTENT_SUMMARY_REPORT, "store_content", s15.SUMMARY_REPORT),
        (M.TM_STORE_STATUS_REPORT, "store_status", s15.STATUS_REPORT),
        (M.TM_STORE_CONFIGURATION_REPORT, "store_configuration", s15.CONFIGURATION),
        (M.TM_STORE_HK_STRUCTURES_REPORT, "stored_hk", s15.STORE_HK),
        (M.TM_STORE_DIAG_STRUCTURES_REPORT, "store_diag_report", s15.STORE_HK),
        (M.TM_STORE_BLOCKED_EVENTS_REPORT, "store_blocked_events", s15.STORE_EVENTS),
        (M.TM_OBCP_STATUS_REPORT, "obcp_status", s18.STATUS_DETAIL),
        (M.TM_OBCP_ABORTED_REPORT, "obcp_aborted", s18.ABORTED),
        (M.TM_EVENT_ACTION_STATUS_REPORT, "event_action_status", s19.STATUS_REPORT),
        (M.TM_EVENT_ACTION_DEFINITIONS_REPORT, "event_actions", s19.DEFINITIONS_REPORT),
        (M.TM_PARAM_VALUE_REPORT, "parameter_values", s20.values_layout(types)),
        (M.TM_PARAM_DEFINITION_REPORT, "parameter_definition_report", s20.DEFINITION_REPORT),
        (M.TM_SEQUENCE_STATUS_REPORT, "sequence_status", s21.STATUS_REPORT),
        (M.TM_SEQUENCE_CHECKSUM_REPORT, "sequence_checksum", s21.CHECKSUM_REPORT),
        (M.TM_SEQUENCE_CONTENT_REPORT, "sequence_content", s21.CONTENT),
        (M.TM_SEQUENCE_ABORTED_REPORT, "sequences_aborted", s21.ABORTED_REPORT),
        (M.TM_POS_SCHED_DETAIL_REPORT, "position_schedule_detail", placed.activities),
        (M.TM_POS_SCHED_SUMMARY_REPORT, "position_schedule_summary", placed.summary),
        (M.TM_POS_SCHED_SUBSCHEDULE_STATUS_REPORT, "position_subschedules", sched.STATUS_REPORT),
        (M.TM_POS_SCHED_GROUP_STATUS_REPORT, "position_groups", sched.STATUS_REPORT),
        (M.TM_FILE_ATTRIBUTE_REPORT, "file_attributes", s23.ATTRIBUTES),
        (M.TM_FILE_FOUND_REPORT, "files_found", s23.FOUND),
        (M.TM_FILE_REPOSITORY_SUMMARY_REPORT, "repository_summary", s23.SUMMARY),
        (M.TM_FILE_COPY_STATUS_REPORT, "copy_status", s23.COPY_STATUS),
    )
    return {msg_type: (name, layout) for msg_type, name, layout in table}
