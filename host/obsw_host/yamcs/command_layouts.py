"""The layout of every standard-service command the XTCE generator writes, by command name.

``COMMANDS`` lists ``(name, (service, subtype), layout, description, arguments)``: ``layout``
is the very ``Structure`` the OBC's service decodes the request with (``req.decode(LAYOUT)``;
a test drives each handler to check that it is), so a command cannot drift from what the OBC
reads. The generator walks the layout field by field (``Generator.layout_command``):

- a field is an argument of its own type, named after the field;
- a repeated group is its count, fixed at 1 (one item per command, as an operator gives it),
  then the item's fields; ``Fixed(0)`` sends an empty group (PUS: N = 0, "all");
- an absolute time (CUC) is its seconds as an argument and a fraction of 0.

``arguments`` maps a field's name to what the walk makes of it beyond that: a new name (a
string), an ``Arg`` (name, labels, valid range) or a ``Fixed`` value. Labels are the
mission's: ``"sid"`` (housekeeping structures), ``"event"``, ``"parameter"``; or a dict.

The commands whose fields come from the database rather than a service layout (service 8
functions, 20 parameter sets, 12 limit checks and functional monitoring, the mission's own
services) are written from the database by the generator itself.
"""

from obsw.pus import messages as M
from obsw.pus.services import s02_device_access as s02
from obsw.pus.services import s03_layouts as s03
from obsw.pus.services import s05_events as s05
from obsw.pus.services import s06_layouts as s06
from obsw.pus.services import s09_time as s09
from obsw.pus.services import s12_layouts as s12
from obsw.pus.services import s15_layouts as s15
from obsw.pus.services import s17_test as s17
from obsw.pus.services import s18_layouts as s18
from obsw.pus.services import s20_parameters as s20
from obsw.pus.services import s21_sequencing as s21
from obsw.pus.services import s22_position_scheduling as s22
from obsw.pus.services import s23_layouts as s23
from obsw.pus.services import schedule_layouts as sched
from obsw.pus.services.report_types import HK_IDS
from obsw.pus.structure import Structure

NONE = Structure([])  # a request without application data


class Arg:
    """A field as an argument: its ``name``, the ``labels`` of its values (a kind the mission
    defines, or a dict), the ``valid`` (low, high) range Yamcs checks before it sends."""

    def __init__(self, name, labels=None, valid=None):
        self.name, self.labels, self.valid = name, labels, valid


class Fixed:
    """A field with a fixed value; ``APID`` stands for the mission's application process."""

    def __init__(self, value):
        self.value = value


APID = "apid"
SID = {"sids": Arg("sid", labels="sid")}
_LEVELS = {0: "none", 1: "procedure", 2: "step", 3: "statement"}
_WINDOWS = {0: "from_to", 1: "after", 2: "before"}
_NO_ARGS = {"id": "obcp", "args": Fixed(0)}


def _each(names, msg_types, layout, arguments=None, description=None):
    return [(n, t, layout, description, arguments or {}) for n, t in zip(names, msg_types)]


COMMANDS = (
    [
        ("ping", M.TC_TEST_ARE_YOU_ALIVE, NONE, "TC[17,1] are you alive", {}),
        (
            "connection_test",
            M.TC_TEST_ON_BOARD_CONNECTION,
            s17.CONNECTION,
            "TC[17,3] on-board connection test",
            {"apid": Arg("target_apid", valid=(0, 2047))},
        ),
    ]
    + _each(
        ("hk_enable", "hk_disable", "hk_one_shot"),
        (M.TC_HK_ENABLE_HK_REPORTS, M.TC_HK_DISABLE_HK_REPORTS, M.TC_HK_ONE_SHOT_HK),
        s03.SIDS,
        SID,
    )
    + [
        (
            "hk_interval",
            M.TC_HK_MODIFY_HK_INTERVAL,
            s03.INTERVALS,
            None,
            {"sid": Arg("sid", labels="sid"), "interval": Arg("interval", valid=(1, 65535))},
        )
    ]
    + _each(
        ("event_enable", "event_disable"),
        (M.TC_EVENT_ENABLE, M.TC_EVENT_DISABLE),
        s05.IDS,
        {"ids": Arg("event", labels="event")},
    )
    + _each(("event_report_disabled",), (M.TC_EVENT_REPORT_DISABLED,), NONE)
    + _each(
        (
            "schedule_enable",
            "schedule_disable",
            "schedule_reset",
            "schedule_detail_all",
            "schedule_summary_all",
        ),
        (
            M.TC_SCHED_ENABLE,
            M.TC_SCHED_DISABLE,
            M.TC_SCHED_RESET,
            M.TC_SCHED_DETAIL_REPORT_ALL,
            M.TC_SCHED_SUMMARY_REPORT_ALL,
        ),
        sched.EMPTY,
    )
    + _each(
        ("monitoring_enable", "monitoring_disable"),
        (
            M.TC_MON_ENABLE_PARAMETER_MONITORING_FUNCTION,
            M.TC_MON_DISABLE_PARAMETER_MONITORING_FUNCTION,
        ),
        s12.EMPTY,
    )
    + _each(
        ("monitors_report",), (M.TC_MON_REPORT_PARAMETER_MONITORING,), s12.IDS, {"ids": Fixed(0)}
    )
    + _each(
        ("monitor_enable", "monitor_disable"),
        (M.TC_MON_ENABLE_PARAMETER_MONITORING, M.TC_MON_DISABLE_PARAMETER_MONITORING),
        s12.IDS,
        {"ids": "pmon"},
    )
    + [
        (
            "parameters_report",
            M.TC_PARAM_REPORT_VALUES,
            s20.IDS,
            "TC[20,1] report one parameter's value",
            {"ids": Arg("parameter", labels="parameter")},
        ),
        (
            "obcp_load",
            M.TC_OBCP_LOAD_DIRECT,
            s18.LOAD,
            "TC[18,1] load a PLUTO procedure given as text",
            _NO_ARGS,
        ),
        (
            "obcp_activate",
            M.TC_OBCP_ACTIVATE,
            s18.ACTIVATE,
            None,
            dict(_NO_ARGS, level=Arg("level", labels=_LEVELS)),
        ),
    ]
    + _each(
        ("obcp_unload", "obcp_stop", "obcp_suspend", "obcp_resume", "obcp_abort"),
        (M.TC_OBCP_UNLOAD, M.TC_OBCP_STOP, M.TC_OBCP_SUSPEND, M.TC_OBCP_RESUME, M.TC_OBCP_ABORT),
        s18.ID,
        {"id": "obcp"},
    )
    + _each(("obcp_abort_all",), (M.TC_OBCP_ABORT_ALL,), s18.EMPTY)
    + [
        ("file_create", M.TC_FILE_CREATE, s23.CREATE, None, {}),
        ("file_delete", M.TC_FILE_DELETE, s23.FILE, None, {}),
        (
            "file_copy",
            M.TC_FILE_COPY,
            s23.COPY,
            "TC[23,14] copy a file (by CFDP between SAT: and GROUND:)",
            {},
        ),
        ("memory_abort_dumps", M.TC_MEM_ABORT_ALL_DUMPS, NONE, "TC[6,12]", {}),
    ]
    + [
        (n, t, s06.ONE_MEMORY, "TC[%d,%d]" % t, {})
        for n, t in (
            ("memory_scrub_enable", M.TC_MEM_ENABLE_SCRUBBING),
            ("memory_scrub_disable", M.TC_MEM_DISABLE_SCRUBBING),
            ("memory_protect", M.TC_MEM_ENABLE_WRITE_PROTECTION),
            ("memory_unprotect", M.TC_MEM_DISABLE_WRITE_PROTECTION),
        )
    ]
    + [
        (n, t, layout, "TC[%d,%d]" % t, {"checksum": "crc"})
        for n, t, layout in (
            ("memory_dump", M.TC_MEM_DUMP_RAW, s06.RANGES),
            ("memory_check", M.TC_MEM_CHECK_RAW, s06.RANGES),
            ("memory_dump_object", M.TC_MEM_DUMP_OBJECT, s06.OBJECT_RANGES),
            ("memory_check_object", M.TC_MEM_CHECK_OBJECT, s06.OBJECT_RANGES),
            ("memory_check_whole_object", M.TC_MEM_CHECK_OBJECT_WHOLE, s06.ONE_OBJECT),
            ("memory_load_file", M.TC_MEM_LOAD_RAW_BY_REFERENCE, s06.LOAD_BY_REFERENCE),
            ("memory_dump_file", M.TC_MEM_DUMP_RAW_TO_FILE, s06.DUMP_TO_FILE),
            (
                "memory_load_object_file",
                M.TC_MEM_LOAD_OBJECT_BY_REFERENCE,
                s06.OBJECT_LOAD_BY_REFERENCE,
            ),
            ("memory_dump_object_file", M.TC_MEM_DUMP_OBJECT_TO_FILE, s06.OBJECT_DUMP_TO_FILE),
        )
    ]
    + [
        (
            "store_copy",
            M.TC_STORE_COPY_BY_TIME_WINDOW,
            s15.COPY_WINDOW,
            "TC[15,24] copy the packets of a time window into an empty store",
            {"window": Arg("window", labels=_WINDOWS)},
        )
    ]
    + [
        (n, t, s15.STORE_HK, "TC[%d,%d]" % t, {"apid": Fixed(APID), "ids": "sid"})
        for n, t in (
            ("store_diag_add", M.TC_STORE_ADD_DIAG_STRUCTURES),
            ("store_diag_delete", M.TC_STORE_DELETE_DIAG_STRUCTURES),
        )
    ]
    + _each(("store_diag_report",), (M.TC_STORE_REPORT_DIAG_STRUCTURES,), s15.ONE_STORE)
    + _each(
        ("sequence_load_file", "sequence_load_file_activate"),
        (M.TC_SEQUENCE_LOAD_BY_REFERENCE, M.TC_SEQUENCE_LOAD_AND_ACTIVATE),
        s21.BY_REFERENCE,
        {"id": "sequence"},
    )
    + _each(("position_set_orbit",), (M.TC_POS_SCHED_SET_ORBIT_NUMBER,), s22.ORBIT)
    + [
        (
            "time_rate",
            M.TC_TIME_SET_REPORT_RATE,
            s09.RATE,
            "TC[9,1] a report every 2**exponent s",
            {"exponent": Arg("exponent", valid=(0, 16))},
        ),
        (
            "device_on_off",
            M.TC_DEVICE_ON_OFF,
            s02.ON_OFF,
            "TC[2,1] on/off device command",
            {"addresses": "address"},
        ),
        (
            "device_register_load",
            M.TC_DEVICE_REGISTER_LOAD,
            s02.REGISTERS,
            "TC[2,2] register load",
            {},
        ),
        (
            "device_register_dump",
            M.TC_DEVICE_REGISTER_DUMP,
            s02.REGISTER_DUMP,
            "TC[2,5] register dump",
            {"addresses": "address"},
        ),
        (
            "device_cpdu",
            M.TC_DEVICE_CPDU,
            s02.CPDU,
            "TC[2,4] CPDU command",
            {"duration": "duration_ms"},
        ),
    ]
    + _each(
        (
            "diag_enable",
            "diag_disable",
            "diag_one_shot",
            "diag_delete",
            "diag_structures",
            "diag_properties",
        ),
        (
            M.TC_HK_ENABLE_DIAG_REPORTS,
            M.TC_HK_DISABLE_DIAG_REPORTS,
            M.TC_HK_ONE_SHOT_DIAG,
            M.TC_HK_DELETE_DIAG_STRUCTURES,
            M.TC_HK_REPORT_DIAG_STRUCTURES,
            M.TC_HK_REPORT_DIAG_PERIODIC_PROPERTIES,
        ),
        s03.SIDS,
        {"sids": "sid"},
    )
    + _each(
        ("diag_interval",),
        (M.TC_HK_MODIFY_DIAG_INTERVAL,),
        s03.INTERVALS,
        {"interval": Arg("interval", valid=(1, 65535))},
    )
    + _each(
        ("hk_append", "diag_append"),
        (M.TC_HK_APPEND_HK_PARAMETERS, M.TC_HK_APPEND_DIAG_PARAMETERS),
        s03.APPEND,
        {"parameters": Arg("parameter", labels="parameter"), "groups": Fixed(0)},
    )
    + _each(
        ("functional_apply", "functional_delete", "functional_report"),
        (
            M.TC_HK_APPLY_FUNCTIONAL_REPORTING,
            M.TC_HK_DELETE_FUNCTIONAL_REPORTING,
            M.TC_HK_REPORT_FUNCTIONAL_REPORTING,
        ),
        s03.FUNCTIONAL_IDS,
        {"ids": "definition"},
    )
    + _each(
        ("forward_diag_add", "forward_diag_delete"),
        (M.TC_FWD_ADD_DIAG_STRUCTURES, M.TC_FWD_DELETE_DIAG_STRUCTURES),
        HK_IDS,
        {"apid": Arg("apid", valid=(0, 2047)), "ids": "sid"},
    )
    + _each(("forward_diag_report",), (M.TC_FWD_REPORT_DIAG_STRUCTURES,), NONE)
)
