# ruff: noqa: E501
# (the standard's names are long; one row per line keeps the table readable)
"""The message types of ECSS-E-ST-70-41C services 1 to 23: the standard's table, as data.

One row per message type: service, subtype, TC or TM, the constant's name in
``obsw.pus.messages``, the standard's name. 318 rows, counted as public PUS-C libraries carry
the standard's tables (spacepackets, puslib, ecss-services). The names of ST[06] 11-22 (atomic
load, dump abort, scrubbing, write protection, load and dump by file) are this project's.
``obsw pus coverage`` compares the OBC's service tables with it.
"""

from collections import namedtuple

MessageType = namedtuple("MessageType", ("service", "subtype", "kind", "name", "title"))

SERVICE_NAMES = {
    1: "request verification",
    2: "device access",
    3: "housekeeping",
    4: "parameter statistics reporting",
    5: "event reporting",
    6: "memory management",
    8: "function management",
    9: "time management",
    11: "time-based scheduling",
    12: "on-board monitoring",
    13: "large packet transfer",
    14: "real-time forwarding control",
    15: "on-board storage and retrieval",
    17: "test",
    18: "on-board operations procedure",
    19: "event-action",
    20: "on-board parameter management",
    21: "request sequencing",
    22: "position-based scheduling",
    23: "file management",
}

_TABLE = """
 1  1 TM TM_VERIFY_ACCEPTANCE_SUCCESS                  successful acceptance verification report
 1  2 TM TM_VERIFY_ACCEPTANCE_FAILURE                  failed acceptance verification report
 1  3 TM TM_VERIFY_START_SUCCESS                       successful start of execution verification report
 1  4 TM TM_VERIFY_START_FAILURE                       failed start of execution verification report
 1  5 TM TM_VERIFY_PROGRESS_SUCCESS                    successful progress of execution verification report
 1  6 TM TM_VERIFY_PROGRESS_FAILURE                    failed progress of execution verification report
 1  7 TM TM_VERIFY_COMPLETION_SUCCESS                  successful completion of execution verification report
 1  8 TM TM_VERIFY_COMPLETION_FAILURE                  failed completion of execution verification report
 1 10 TM TM_VERIFY_ROUTING_FAILURE                     failed routing verification report
 2  1 TC TC_DEVICE_ON_OFF                              distribute on/off device commands
 2  2 TC TC_DEVICE_REGISTER_LOAD                       distribute register load commands
 2  4 TC TC_DEVICE_CPDU                                distribute CPDU commands
 2  5 TC TC_DEVICE_REGISTER_DUMP                       dump register data
 2  6 TM TM_DEVICE_REGISTER_DUMP_REPORT                register data dump report
 2  7 TC TC_DEVICE_PHYSICAL_COMMAND                    distribute physical device commands
 2  8 TC TC_DEVICE_PHYSICAL_ACQUIRE                    acquire data from physical devices
 2  9 TM TM_DEVICE_PHYSICAL_DATA_REPORT                physical device data report
 2 10 TC TC_DEVICE_LOGICAL_COMMAND                     distribute logical device commands
 2 11 TC TC_DEVICE_LOGICAL_ACQUIRE                     acquire data from logical devices
 2 12 TM TM_DEVICE_LOGICAL_DATA_REPORT                 logical device data report
 3  1 TC TC_HK_CREATE_HK_STRUCTURE                     create a housekeeping parameter report structure
 3  2 TC TC_HK_CREATE_DIAG_STRUCTURE                   create a diagnostic parameter report structure
 3  3 TC TC_HK_DELETE_HK_STRUCTURES                    delete housekeeping parameter report structures
 3  4 TC TC_HK_DELETE_DIAG_STRUCTURES                  delete diagnostic parameter report structures
 3  5 TC TC_HK_ENABLE_HK_REPORTS                       enable the periodic generation of housekeeping parameter reports
 3  6 TC TC_HK_DISABLE_HK_REPORTS                      disable the periodic generation of housekeeping parameter reports
 3  7 TC TC_HK_ENABLE_DIAG_REPORTS                     enable the periodic generation of diagnostic parameter reports
 3  8 TC TC_HK_DISABLE_DIAG_REPORTS                    disable the periodic generation of diagnostic parameter reports
 3  9 TC TC_HK_REPORT_HK_STRUCTURES                    report housekeeping parameter report structures
 3 10 TM TM_HK_HK_STRUCTURE_REPORT                     housekeeping parameter report structure report
 3 11 TC TC_HK_REPORT_DIAG_STRUCTURES                  report diagnostic parameter report structures
 3 12 TM TM_HK_DIAG_STRUCTURE_REPORT                   diagnostic parameter report structure report
 3 25 TM TM_HK_HK_REPORT                               housekeeping parameter report
 3 26 TM TM_HK_DIAG_REPORT                             diagnostic parameter report
 3 27 TC TC_HK_ONE_SHOT_HK                             generate a one shot report for housekeeping parameter report structures
 3 28 TC TC_HK_ONE_SHOT_DIAG                           generate a one shot report for diagnostic parameter report structures
 3 29 TC TC_HK_APPEND_HK_PARAMETERS                    append parameters to a housekeeping parameter report structure
 3 30 TC TC_HK_APPEND_DIAG_PARAMETERS                  append parameters to a diagnostic parameter report structure
 3 31 TC TC_HK_MODIFY_HK_INTERVAL                      modify the collection interval of housekeeping parameter report structures
 3 32 TC TC_HK_MODIFY_DIAG_INTERVAL                    modify the collection interval of diagnostic parameter report structures
 3 33 TC TC_HK_REPORT_HK_PERIODIC_PROPERTIES           report the periodic generation properties of housekeeping parameter report structures
 3 34 TC TC_HK_REPORT_DIAG_PERIODIC_PROPERTIES         report the periodic generation properties of diagnostic parameter report structures
 3 35 TM TM_HK_HK_PERIODIC_PROPERTIES_REPORT           housekeeping parameter report periodic generation properties report
 3 36 TM TM_HK_DIAG_PERIODIC_PROPERTIES_REPORT         diagnostic parameter report periodic generation properties report
 3 37 TC TC_HK_APPLY_FUNCTIONAL_REPORTING              apply parameter functional reporting configurations
 3 38 TC TC_HK_CREATE_FUNCTIONAL_REPORTING             create a parameter functional reporting definition
 3 39 TC TC_HK_DELETE_FUNCTIONAL_REPORTING             delete parameter functional reporting definitions
 3 40 TC TC_HK_REPORT_FUNCTIONAL_REPORTING             report parameter functional reporting definitions
 3 41 TM TM_HK_FUNCTIONAL_REPORTING_REPORT             parameter functional reporting definition report
 3 42 TC TC_HK_ADD_TO_FUNCTIONAL_REPORTING             add parameter report definitions to a parameter functional reporting definition
 3 43 TC TC_HK_REMOVE_FROM_FUNCTIONAL_REPORTING        remove parameter report definitions from a parameter functional reporting definition
 3 44 TC TC_HK_MODIFY_FUNCTIONAL_REPORTING_PERIODS     modify the periodic generation properties of parameter report definitions of a parameter functional reporting definition
 4  1 TC TC_STATS_REPORT                               report the parameter statistics
 4  2 TM TM_STATS_REPORT                               parameter statistics report
 4  3 TC TC_STATS_RESET                                reset the parameter statistics
 4  4 TC TC_STATS_ENABLE_PERIODIC                      enable the periodic parameter statistics reporting
 4  5 TC TC_STATS_DISABLE_PERIODIC                     disable the periodic parameter statistics reporting
 4  6 TC TC_STATS_ADD_DEFINITIONS                      add or update parameter statistics definitions
 4  7 TC TC_STATS_DELETE_DEFINITIONS                   delete parameter statistics definitions
 4  8 TC TC_STATS_REPORT_DEFINITIONS                   report the parameter statistics definitions
 4  9 TM TM_STATS_DEFINITIONS_REPORT                   parameter statistics definition report
 5  1 TM TM_EVENT_INFORMATIVE                          informative event report
 5  2 TM TM_EVENT_LOW_SEVERITY                         low severity anomaly report
 5  3 TM TM_EVENT_MEDIUM_SEVERITY                      medium severity anomaly report
 5  4 TM TM_EVENT_HIGH_SEVERITY                        high severity anomaly report
 5  5 TC TC_EVENT_ENABLE                               enable the report generation of event definitions
 5  6 TC TC_EVENT_DISABLE                              disable the report generation of event definitions
 5  7 TC TC_EVENT_REPORT_DISABLED                      report the list of disabled event definitions
 5  8 TM TM_EVENT_DISABLED_LIST_REPORT                 disabled event definitions list report
 6  1 TC TC_MEM_LOAD_OBJECT                            load object memory data
 6  2 TC TC_MEM_LOAD_RAW                               load raw memory data
 6  3 TC TC_MEM_DUMP_OBJECT                            dump object memory data
 6  4 TM TM_MEM_DUMP_OBJECT_REPORT                     dumped object memory data report
 6  5 TC TC_MEM_DUMP_RAW                               dump raw memory data
 6  6 TM TM_MEM_DUMP_RAW_REPORT                        dumped raw memory data report
 6  7 TC TC_MEM_CHECK_OBJECT                           check object memory data
 6  8 TM TM_MEM_CHECK_OBJECT_REPORT                    checked object memory data report
 6  9 TC TC_MEM_CHECK_RAW                              check raw memory data
 6 10 TM TM_MEM_CHECK_RAW_REPORT                       checked raw memory data report
 6 11 TC TC_MEM_LOAD_RAW_ATOMIC                        load raw memory data areas atomically
 6 12 TC TC_MEM_ABORT_ALL_DUMPS                        abort all memory dumps
 6 13 TC TC_MEM_ENABLE_SCRUBBING                       enable the memory scrubbing
 6 14 TC TC_MEM_DISABLE_SCRUBBING                      disable the memory scrubbing
 6 15 TC TC_MEM_ENABLE_WRITE_PROTECTION                enable the write protection of a memory
 6 16 TC TC_MEM_DISABLE_WRITE_PROTECTION               disable the write protection of a memory
 6 17 TC TC_MEM_CHECK_OBJECT_WHOLE                     check a whole memory object
 6 18 TM TM_MEM_CHECK_OBJECT_WHOLE_REPORT              checked whole memory object report
 6 19 TC TC_MEM_LOAD_RAW_BY_REFERENCE                  load raw memory data areas by reference
 6 20 TC TC_MEM_DUMP_RAW_TO_FILE                       dump raw memory data areas to file
 6 21 TC TC_MEM_LOAD_OBJECT_BY_REFERENCE               load object memory data areas by reference
 6 22 TC TC_MEM_DUMP_OBJECT_TO_FILE                    dump object memory data areas to file
 8  1 TC TC_FUNCTION_PERFORM                           perform a function
 9  1 TC TC_TIME_SET_REPORT_RATE                       set the time report generation rate
 9  2 TM TM_TIME_CUC_REPORT                            CUC time report
 9  3 TM TM_TIME_CDS_REPORT                            CDS time report
11  1 TC TC_SCHED_ENABLE                               enable the time-based schedule execution function
11  2 TC TC_SCHED_DISABLE                              disable the time-based schedule execution function
11  3 TC TC_SCHED_RESET                                reset the time-based schedule
11  4 TC TC_SCHED_INSERT                               insert activities into the time-based schedule
11  5 TC TC_SCHED_DELETE_BY_ID                         delete time-based scheduled activities identified by request identifier
11  6 TC TC_SCHED_DELETE_BY_FILTER                     delete the time-based scheduled activities identified by a filter
11  7 TC TC_SCHED_TIME_SHIFT_BY_ID                     time-shift scheduled activities identified by request identifier
11  8 TC TC_SCHED_TIME_SHIFT_BY_FILTER                 time-shift the scheduled activities identified by a filter
11  9 TC TC_SCHED_DETAIL_REPORT_BY_ID                  detail-report time-based scheduled activities identified by request identifier
11 10 TM TM_SCHED_DETAIL_REPORT                        time-based schedule detail report
11 11 TC TC_SCHED_DETAIL_REPORT_BY_FILTER              detail-report the time-based scheduled activities identified by a filter
11 12 TC TC_SCHED_SUMMARY_REPORT_BY_ID                 summary-report time-based scheduled activities identified by request identifier
11 13 TM TM_SCHED_SUMMARY_REPORT                       time-based schedule summary report
11 14 TC TC_SCHED_SUMMARY_REPORT_BY_FILTER             summary-report the time-based scheduled activities identified by a filter
11 15 TC TC_SCHED_TIME_SHIFT_ALL                       time-shift all scheduled activities
11 16 TC TC_SCHED_DETAIL_REPORT_ALL                    detail-report all time-based scheduled activities
11 17 TC TC_SCHED_SUMMARY_REPORT_ALL                   summary-report all time-based scheduled activities
11 18 TC TC_SCHED_REPORT_SUBSCHEDULE_STATUS            report the status of each time-based sub-schedule
11 19 TM TM_SCHED_SUBSCHEDULE_STATUS_REPORT            time-based sub-schedule status report
11 20 TC TC_SCHED_ENABLE_SUBSCHEDULES                  enable time-based sub-schedules
11 21 TC TC_SCHED_DISABLE_SUBSCHEDULES                 disable time-based sub-schedules
11 22 TC TC_SCHED_CREATE_GROUPS                        create time-based scheduling groups
11 23 TC TC_SCHED_DELETE_GROUPS                        delete time-based scheduling groups
11 24 TC TC_SCHED_ENABLE_GROUPS                        enable time-based scheduling groups
11 25 TC TC_SCHED_DISABLE_GROUPS                       disable time-based scheduling groups
11 26 TC TC_SCHED_REPORT_GROUP_STATUS                  report the status of each time-based scheduling group
11 27 TM TM_SCHED_GROUP_STATUS_REPORT                  time-based scheduling group status report
12  1 TC TC_MON_ENABLE_PARAMETER_MONITORING            enable parameter monitoring definitions
12  2 TC TC_MON_DISABLE_PARAMETER_MONITORING           disable parameter monitoring definitions
12  3 TC TC_MON_CHANGE_TRANSITION_DELAY                change the maximum transition reporting delay
12  4 TC TC_MON_DELETE_ALL_PARAMETER_MONITORING        delete all parameter monitoring definitions
12  5 TC TC_MON_ADD_PARAMETER_MONITORING               add parameter monitoring definitions
12  6 TC TC_MON_DELETE_PARAMETER_MONITORING            delete parameter monitoring definitions
12  7 TC TC_MON_MODIFY_PARAMETER_MONITORING            modify parameter monitoring definitions
12  8 TC TC_MON_REPORT_PARAMETER_MONITORING            report parameter monitoring definitions
12  9 TM TM_MON_PARAMETER_MONITORING_REPORT            parameter monitoring definition report
12 10 TC TC_MON_REPORT_OUT_OF_LIMITS                   report the out-of-limits
12 11 TM TM_MON_OUT_OF_LIMITS_REPORT                   out-of-limits report
12 12 TM TM_MON_CHECK_TRANSITION_REPORT                check transition report
12 13 TC TC_MON_REPORT_PARAMETER_MONITORING_STATUS     report the status of each parameter monitoring definition
12 14 TM TM_MON_PARAMETER_MONITORING_STATUS_REPORT     parameter monitoring definition status report
12 15 TC TC_MON_ENABLE_PARAMETER_MONITORING_FUNCTION   enable the parameter monitoring function
12 16 TC TC_MON_DISABLE_PARAMETER_MONITORING_FUNCTION  disable the parameter monitoring function
12 17 TC TC_MON_ENABLE_FUNCTIONAL_MONITORING_FUNCTION  enable the functional monitoring function
12 18 TC TC_MON_DISABLE_FUNCTIONAL_MONITORING_FUNCTION disable the functional monitoring function
12 19 TC TC_MON_ENABLE_FUNCTIONAL_MONITORING           enable functional monitoring definitions
12 20 TC TC_MON_DISABLE_FUNCTIONAL_MONITORING          disable functional monitoring definitions
12 21 TC TC_MON_PROTECT_FUNCTIONAL_MONITORING          protect functional monitoring definitions
12 22 TC TC_MON_UNPROTECT_FUNCTIONAL_MONITORING        unprotect functional monitoring definitions
12 23 TC TC_MON_ADD_FUNCTIONAL_MONITORING              add functional monitoring definitions
12 24 TC TC_MON_DELETE_FUNCTIONAL_MONITORING           delete functional monitoring definitions
12 25 TC TC_MON_REPORT_FUNCTIONAL_MONITORING           report functional monitoring definitions
12 26 TM TM_MON_FUNCTIONAL_MONITORING_REPORT           functional monitoring definition report
12 27 TC TC_MON_REPORT_FUNCTIONAL_MONITORING_STATUS    report the status of each functional monitoring definition
12 28 TM TM_MON_FUNCTIONAL_MONITORING_STATUS_REPORT    functional monitoring definition status report
13  1 TM TM_LARGE_DOWNLINK_FIRST                       first downlink part report
13  2 TM TM_LARGE_DOWNLINK_INTERMEDIATE                intermediate downlink part report
13  3 TM TM_LARGE_DOWNLINK_LAST                        last downlink part report
13  9 TC TC_LARGE_UPLINK_FIRST                         first uplink part
13 10 TC TC_LARGE_UPLINK_INTERMEDIATE                  intermediate uplink part
13 11 TC TC_LARGE_UPLINK_LAST                          last uplink part
13 16 TM TM_LARGE_UPLINK_ABORTION                      large packet uplink abortion report
14  1 TC TC_FWD_ADD_REPORT_TYPES                       add report types to the application process forward-control configuration
14  2 TC TC_FWD_DELETE_REPORT_TYPES                    delete report types from the application process forward-control configuration
14  3 TC TC_FWD_REPORT_REPORT_TYPES                    report the content of the application process forward-control configuration
14  4 TM TM_FWD_REPORT_TYPES_REPORT                    application process forward-control configuration content report
14  5 TC TC_FWD_ADD_HK_STRUCTURES                      add structure identifiers to the housekeeping parameter report forward-control configuration
14  6 TC TC_FWD_DELETE_HK_STRUCTURES                   delete structure identifiers from the housekeeping parameter report forward-control configuration
14  7 TC TC_FWD_REPORT_HK_STRUCTURES                   report the content of the housekeeping parameter report forward-control configuration
14  8 TM TM_FWD_HK_STRUCTURES_REPORT                   housekeeping parameter report forward-control configuration content report
14  9 TC TC_FWD_ADD_DIAG_STRUCTURES                    add structure identifiers to the diagnostic parameter report forward-control configuration
14 10 TC TC_FWD_DELETE_DIAG_STRUCTURES                 delete structure identifiers from the diagnostic parameter report forward-control configuration
14 11 TC TC_FWD_REPORT_DIAG_STRUCTURES                 report the content of the diagnostic parameter report forward-control configuration
14 12 TM TM_FWD_DIAG_STRUCTURES_REPORT                 diagnostic parameter report forward-control configuration content report
14 13 TC TC_FWD_DELETE_BLOCKED_EVENTS                  delete event definition identifiers from the event report blocking forward-control configuration
14 14 TC TC_FWD_ADD_BLOCKED_EVENTS                     add event definition identifiers to the event report blocking forward-control configuration
14 15 TC TC_FWD_REPORT_BLOCKED_EVENTS                  report the content of the event report blocking forward-control configuration
14 16 TM TM_FWD_BLOCKED_EVENTS_REPORT                  event report blocking forward-control configuration content report
15  1 TC TC_STORE_ENABLE_STORAGE                       enable the storage function of packet stores
15  2 TC TC_STORE_DISABLE_STORAGE                      disable the storage function of packet stores
15  3 TC TC_STORE_ADD_REPORT_TYPES                     add report types to the application process storage-control configuration
15  4 TC TC_STORE_DELETE_REPORT_TYPES                  delete report types from the application process storage-control configuration
15  5 TC TC_STORE_REPORT_REPORT_TYPES                  report the content of the application process storage-control configuration
15  6 TM TM_STORE_REPORT_TYPES_REPORT                  application process storage-control configuration content report
15  9 TC TC_STORE_START_TIME_RANGE_RETRIEVAL           start the by-time-range retrieval of packet stores
15 11 TC TC_STORE_DELETE_CONTENT_UP_TO                 delete the packet store content up to the specified time
15 12 TC TC_STORE_REPORT_CONTENT_SUMMARY               summary-report the content of packet stores
15 13 TM TM_STORE_CONTENT_SUMMARY_REPORT               packet store content summary report
15 14 TC TC_STORE_CHANGE_OPEN_RETRIEVAL_START          change the open retrieval start time tag
15 15 TC TC_STORE_RESUME_OPEN_RETRIEVAL                resume the open retrieval of packet stores
15 16 TC TC_STORE_SUSPEND_OPEN_RETRIEVAL               suspend the open retrieval of packet stores
15 17 TC TC_STORE_ABORT_TIME_RANGE_RETRIEVAL           abort the by-time-range retrieval of packet stores
15 18 TC TC_STORE_REPORT_STATUS                        report the status of each packet store
15 19 TM TM_STORE_STATUS_REPORT                        packet store status report
15 20 TC TC_STORE_CREATE                               create packet stores
15 21 TC TC_STORE_DELETE                               delete packet stores
15 22 TC TC_STORE_REPORT_CONFIGURATION                 report the packet store configuration
15 23 TM TM_STORE_CONFIGURATION_REPORT                 packet store configuration report
15 24 TC TC_STORE_COPY_BY_TIME_WINDOW                  copy the packet store content
15 25 TC TC_STORE_RESIZE                               resize packet stores
15 26 TC TC_STORE_MAKE_CIRCULAR                        change a packet store type to circular
15 27 TC TC_STORE_MAKE_BOUNDED                         change a packet store type to bounded
15 28 TC TC_STORE_CHANGE_VIRTUAL_CHANNEL               change the virtual channel used by a packet store
15 29 TC TC_STORE_ADD_HK_STRUCTURES                    add structure identifiers to the housekeeping parameter report storage-control configuration
15 30 TC TC_STORE_DELETE_HK_STRUCTURES                 delete structure identifiers from the housekeeping parameter report storage-control configuration
15 31 TC TC_STORE_ADD_DIAG_STRUCTURES                  add structure identifiers to the diagnostic parameter report storage-control configuration
15 32 TC TC_STORE_DELETE_DIAG_STRUCTURES               delete structure identifiers from the diagnostic parameter report storage-control configuration
15 33 TC TC_STORE_DELETE_BLOCKED_EVENTS                delete event definition identifiers from the event report blocking storage-control configuration
15 34 TC TC_STORE_ADD_BLOCKED_EVENTS                   add event definition identifiers to the event report blocking storage-control configuration
15 35 TC TC_STORE_REPORT_HK_STRUCTURES                 report the content of the housekeeping parameter report storage-control configuration
15 36 TM TM_STORE_HK_STRUCTURES_REPORT                 housekeeping parameter report storage-control configuration content report
15 37 TC TC_STORE_REPORT_DIAG_STRUCTURES               report the content of the diagnostic parameter report storage-control configuration
15 38 TM TM_STORE_DIAG_STRUCTURES_REPORT               diagnostic parameter report storage-control configuration content report
15 39 TC TC_STORE_REPORT_BLOCKED_EVENTS                report the content of the event report blocking storage-control configuration
15 40 TM TM_STORE_BLOCKED_EVENTS_REPORT                event report blocking storage-control configuration content report
17  1 TC TC_TEST_ARE_YOU_ALIVE                         perform an are-you-alive connection test
17  2 TM TM_TEST_ARE_YOU_ALIVE_REPORT                  are-you-alive connection test report
17  3 TC TC_TEST_ON_BOARD_CONNECTION                   perform an on-board connection test
17  4 TM TM_TEST_ON_BOARD_CONNECTION_REPORT            on-board connection test report
18  1 TC TC_OBCP_LOAD_DIRECT                           load OBCPs directly
18  2 TC TC_OBCP_UNLOAD                                unload OBCPs
18  3 TC TC_OBCP_ACTIVATE                              activate OBCPs
18  4 TC TC_OBCP_STOP                                  stop OBCPs
18  5 TC TC_OBCP_SUSPEND                               suspend OBCPs
18  6 TC TC_OBCP_RESUME                                resume OBCPs
18  7 TC TC_OBCP_COMMUNICATE_PARAMETERS                communicate parameters to an OBCP
18  8 TC TC_OBCP_REPORT_STATUS                         report the status of each OBCP
18  9 TM TM_OBCP_STATUS_REPORT                         OBCP status report
18 12 TC TC_OBCP_ABORT                                 abort OBCPs
18 13 TC TC_OBCP_LOAD_BY_REFERENCE                     load OBCPs by reference
18 14 TC TC_OBCP_ACTIVATE_AND_STEP                     activate and execute one OBCP step
18 15 TC TC_OBCP_RESUME_AND_STEP                       resume and execute one OBCP step
18 16 TC TC_OBCP_SET_OBSERVABILITY                     set the observability level of OBCPs
18 17 TC TC_OBCP_ABORT_ALL                             abort all OBCPs and report
18 18 TM TM_OBCP_ABORTED_REPORT                        aborted OBCP report
18 19 TC TC_OBCP_LOAD_AND_ACTIVATE                     load by reference and activate OBCPs
18 20 TC TC_OBCP_STOP_AND_UNLOAD                       stop and unload OBCPs
18 21 TC TC_OBCP_START_ENGINE                          start the OBCP engine
18 22 TC TC_OBCP_STOP_ENGINE                           stop the OBCP engine
19  1 TC TC_EVENT_ACTION_ADD                           add event-action definitions
19  2 TC TC_EVENT_ACTION_DELETE                        delete event-action definitions
19  3 TC TC_EVENT_ACTION_DELETE_ALL                    delete all event-action definitions
19  4 TC TC_EVENT_ACTION_ENABLE                        enable event-action definitions
19  5 TC TC_EVENT_ACTION_DISABLE                       disable event-action definitions
19  6 TC TC_EVENT_ACTION_REPORT_STATUS                 report the status of each event-action definition
19  7 TM TM_EVENT_ACTION_STATUS_REPORT                 event-action status report
19  8 TC TC_EVENT_ACTION_ENABLE_FUNCTION               enable the event-action function
19  9 TC TC_EVENT_ACTION_DISABLE_FUNCTION              disable the event-action function
19 10 TC TC_EVENT_ACTION_REPORT_DEFINITIONS            report event-action definitions
19 11 TM TM_EVENT_ACTION_DEFINITIONS_REPORT            event-action definition report
20  1 TC TC_PARAM_REPORT_VALUES                        report parameter values
20  2 TM TM_PARAM_VALUE_REPORT                         parameter value report
20  3 TC TC_PARAM_SET_VALUES                           set parameter values
20  4 TC TC_PARAM_CHANGE_RAW_MEMORY_DEFINITIONS        change raw memory parameter definitions
20  5 TC TC_PARAM_CHANGE_OBJECT_MEMORY_DEFINITIONS     change object memory parameter definitions
20  6 TC TC_PARAM_REPORT_DEFINITIONS                   report parameter definitions
20  7 TM TM_PARAM_DEFINITION_REPORT                    parameter definition report
21  1 TC TC_SEQUENCE_LOAD_DIRECT                       load a request sequence directly
21  2 TC TC_SEQUENCE_LOAD_BY_REFERENCE                 load a request sequence by reference
21  3 TC TC_SEQUENCE_UNLOAD                            unload a request sequence
21  4 TC TC_SEQUENCE_ACTIVATE                          activate a request sequence
21  5 TC TC_SEQUENCE_ABORT                             abort a request sequence
21  6 TC TC_SEQUENCE_REPORT_STATUS                     report the execution status of each request sequence
21  7 TM TM_SEQUENCE_STATUS_REPORT                     request sequence execution status report
21  8 TC TC_SEQUENCE_LOAD_AND_ACTIVATE                 load by reference and activate a request sequence
21  9 TC TC_SEQUENCE_CHECKSUM                          checksum a request sequence
21 10 TM TM_SEQUENCE_CHECKSUM_REPORT                   request sequence checksum report
21 11 TC TC_SEQUENCE_REPORT_CONTENT                    report the content of a request sequence
21 12 TM TM_SEQUENCE_CONTENT_REPORT                    request sequence content report
21 13 TC TC_SEQUENCE_ABORT_ALL                         abort all request sequences and report
21 14 TM TM_SEQUENCE_ABORTED_REPORT                    aborted request sequence report
22  1 TC TC_POS_SCHED_ENABLE                           enable the position-based schedule execution function
22  2 TC TC_POS_SCHED_DISABLE                          disable the position-based schedule execution function
22  3 TC TC_POS_SCHED_RESET                            reset the position-based schedule
22  4 TC TC_POS_SCHED_INSERT                           insert activities into the position-based schedule
22  5 TC TC_POS_SCHED_DELETE_BY_ID                     delete position-based scheduled activities identified by request identifier
22  6 TC TC_POS_SCHED_DELETE_BY_FILTER                 delete the position-based scheduled activities identified by a filter
22  7 TC TC_POS_SCHED_POSITION_SHIFT_BY_ID             position-shift scheduled activities identified by request identifier
22  8 TC TC_POS_SCHED_POSITION_SHIFT_BY_FILTER         position-shift the scheduled activities identified by a filter
22  9 TC TC_POS_SCHED_DETAIL_REPORT_BY_ID              detail-report position-based scheduled activities identified by request identifier
22 10 TM TM_POS_SCHED_DETAIL_REPORT                    position-based schedule detail report
22 11 TC TC_POS_SCHED_DETAIL_REPORT_BY_FILTER          detail-report the position-based scheduled activities identified by a filter
22 12 TC TC_POS_SCHED_SUMMARY_REPORT_BY_ID             summary-report position-based scheduled activities identified by request identifier
22 13 TM TM_POS_SCHED_SUMMARY_REPORT                   position-based schedule summary report
22 14 TC TC_POS_SCHED_SUMMARY_REPORT_BY_FILTER         summary-report the position-based scheduled activities identified by a filter
22 15 TC TC_POS_SCHED_POSITION_SHIFT_ALL               position-shift all scheduled activities
22 16 TC TC_POS_SCHED_DETAIL_REPORT_ALL                detail-report all position-based scheduled activities
22 17 TC TC_POS_SCHED_SUMMARY_REPORT_ALL               summary-report all position-based scheduled activities
22 18 TC TC_POS_SCHED_REPORT_SUBSCHEDULE_STATUS        report the status of each position-based sub-schedule
22 19 TM TM_POS_SCHED_SUBSCHEDULE_STATUS_REPORT        position-based sub-schedule status report
22 20 TC TC_POS_SCHED_ENABLE_SUBSCHEDULES              enable position-based sub-schedules
22 21 TC TC_POS_SCHED_DISABLE_SUBSCHEDULES             disable position-based sub-schedules
22 22 TC TC_POS_SCHED_CREATE_GROUPS                    create position-based scheduling groups
22 23 TC TC_POS_SCHED_DELETE_GROUPS                    delete position-based scheduling groups
22 24 TC TC_POS_SCHED_ENABLE_GROUPS                    enable position-based scheduling groups
22 25 TC TC_POS_SCHED_DISABLE_GROUPS                   disable position-based scheduling groups
22 26 TC TC_POS_SCHED_REPORT_GROUP_STATUS              report the status of each position-based scheduling group
22 27 TM TM_POS_SCHED_GROUP_STATUS_REPORT              position-based scheduling group status report
22 28 TC TC_POS_SCHED_SET_ORBIT_NUMBER                 set the orbit number
23  1 TC TC_FILE_CREATE                                create a file
23  2 TC TC_FILE_DELETE                                delete a file
23  3 TC TC_FILE_REPORT_ATTRIBUTES                     report the attributes of a file
23  4 TM TM_FILE_ATTRIBUTE_REPORT                      file attribute report
23  5 TC TC_FILE_LOCK                                  lock a file
23  6 TC TC_FILE_UNLOCK                                unlock a file
23  7 TC TC_FILE_FIND                                  find files
23  8 TM TM_FILE_FOUND_REPORT                          found files report
23  9 TC TC_FILE_CREATE_DIRECTORY                      create a directory
23 10 TC TC_FILE_DELETE_DIRECTORY                      delete a directory
23 11 TC TC_FILE_RENAME_DIRECTORY                      rename a directory
23 12 TC TC_FILE_REPORT_REPOSITORY_SUMMARY             report the summary content of a repository
23 13 TM TM_FILE_REPOSITORY_SUMMARY_REPORT             repository content summary report
23 14 TC TC_FILE_COPY                                  copy a file
23 15 TC TC_FILE_MOVE                                  move a file
23 16 TC TC_FILE_SUSPEND_COPY                          suspend file copy operations
23 17 TC TC_FILE_RESUME_COPY                           resume file copy operations
23 18 TC TC_FILE_ABORT_COPY                            abort file copy operations
23 19 TC TC_FILE_SUSPEND_COPY_IN_PATH                  suspend all file copy operations involving a repository path
23 20 TC TC_FILE_RESUME_COPY_IN_PATH                   resume all file copy operations involving a repository path
23 21 TC TC_FILE_ABORT_COPY_IN_PATH                    abort all file copy operations involving a repository path
23 22 TC TC_FILE_ENABLE_COPY_STATUS_REPORTS            enable the periodic reporting of the file copy status
23 23 TM TM_FILE_COPY_STATUS_REPORT                    file copy status report
23 24 TC TC_FILE_DISABLE_COPY_STATUS_REPORTS           disable the periodic reporting of the file copy status
"""


def _parse(text):
    out = []
    for line in text.strip().splitlines():
        service, subtype, kind, name, title = line.split(None, 4)
        out.append(MessageType(int(service), int(subtype), kind, name, title))
    return tuple(out)


MESSAGE_TYPES = _parse(_TABLE)


def by_service():
    """{service: [MessageType, ...]} in the standard's order."""
    out = {}
    for m in MESSAGE_TYPES:
        out.setdefault(m.service, []).append(m)
    return out
