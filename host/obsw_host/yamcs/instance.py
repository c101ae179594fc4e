"""A complete Yamcs instance for the spacecraft: server and instance configuration, MDB, SQL.

``write_instance(folder, spacecraft, ...)`` writes ``etc/`` (yamcs.yaml, yamcs.INSTANCE.yaml,
processor.yaml, extra_streams.sql, events.json), ``mdb/MISSION.xml`` and the CFDP buckets of
each instance, ``files/INSTANCE/up`` (Yamcs sends from there) and ``files/INSTANCE/down``
(what Yamcs receives). Yamcs is
started with that folder as its working directory (see ``server``).

Two link modes, every socket on loopback:
- ``packets``: Yamcs connects by TCP to the packet gateway (``gateway.PacketGateway``): one
  connection carries PUS TM and TC, one carries CFDP TM; TCs go out on the first.
- ``frames``: Yamcs sends TC transfer frames in CLTUs by UDP to the frame processor (its FOP-1
  runs COP-1 against our FARM-1 on VC 0; no segment header, since Yamcs 5.12.8 fails on MAP
  IDs for the commands of its own services, CFDP's among them: ``TcPacketHandler.getMapId``
  reads the ancillary data of a MetaCommand they do not have; docs/yamcs.md) and receives TM
  transfer frames by UDP (the mission's virtual channels: real time, playback, CFDP and
  essential, from the spacecraft database's ``frames`` plan; idle frames and the CLCW in the
  OCF).

The spacecraft id, the virtual channels, the CFDP entities (the database's onboard filestore
and the first other one, whatever their prefixes) and the CFDP APID come from the mission
(``obsw_host.mission.ids.MissionIds``); a missing one is an error naming the file and key.
"""

import json
import os

from obsw_host.mission.ports import Ports
from obsw_host.yamcs.xtce import event_templates, generate

INSTANCE = "obsw"  # the instance of library callers that name none (the CLI names the mission)
_DEFAULT = Ports()  # the ports of this run without a mission file (obsw_host.mission.ports)
HTTP_PORT = _DEFAULT.yamcs_http
# the default ports of the ground side of the links (all on 127.0.0.1)
PORTS = _DEFAULT.yamcs()


def _yaml(value, indent=0):
    """A small YAML writer for the plain dicts, lists, strings and numbers of a config."""
    pad = "  " * indent
    out = []
    if isinstance(value, dict):
        for k, v in value.items():
            if isinstance(v, (dict, list)) and v:
                out.append("%s%s:" % (pad, k))
                out.append(_yaml(v, indent + 1))
            else:
                out.append("%s%s: %s" % (pad, k, _scalar(v)))
    elif isinstance(value, list):
        for v in value:
            if isinstance(v, dict) and v:
                inner = _yaml(v, indent + 1).split("\n")
                out.append("%s- %s" % (pad, inner[0].strip()))
                out.extend(inner[1:])
            else:
                out.append("%s- %s" % (pad, _scalar(v)))
    return "\n".join(out)


def _scalar(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return repr(v)
    if isinstance(v, (dict, list)):
        return "{}" if isinstance(v, dict) else "[]"
    return json.dumps(str(v))


def pus_tm_args(config=None):
    """The PusPacketPreprocessor arguments for the OBC's TM layout (CRC, CUC TAI time)."""
    from obsw.pus.config import PusConfig

    cfg = config or PusConfig()
    t = cfg.time
    # CUC P-field: time code id 001 (1958 TAI epoch), coarse octets - 1, fine octets
    pfield = 0x10 | (t.coarse - 1) << 2 | t.fine
    return {
        "errorDetection": {"type": "CRC-16-CCIIT"},
        "pktTimeOffset": 6 + 3 + cfg.message_counter_size + cfg.destination_id_size,
        "timeEncoding": {"type": "CUC", "epoch": "TAI", "implicitPField": pfield},
    }


PUS_TC_ARGS = {"errorDetection": {"type": "CRC-16-CCIIT"}}
CFDP_TM_ARGS = {"timestampOffset": -1, "seqCountOffset": -1, "useLocalGenerationTime": True}


def instance_name(name):
    """A Yamcs instance name for mission ``name`` (letters, digits, '_', '-', '.')."""
    out = "".join(c if c.isalnum() or c in "_-." else "_" for c in str(name))
    return out if out and (out[0].isalnum() or out[0] == "_") else "m" + out


def links(mode, ports, ids):
    """The dataLinks section for ``mode`` ('packets' or 'frames') of the mission ``ids``."""
    tm_args = pus_tm_args(ids.pus_config)
    if mode == "packets":
        return [
            {
                "name": "pus",
                "class": "org.yamcs.tctm.TcpTcTmDataLink",
                "tmStream": "tm_realtime",
                "tcStream": "tc_realtime",
                "host": "127.0.0.1",
                "port": ports["pus"],
                "packetPreprocessorClassName": "org.yamcs.pus.PusPacketPreprocessor",
                "packetPreprocessorArgs": tm_args,
                "commandPostprocessorClassName": "org.yamcs.pus.PusCommandPostprocessor",
                "commandPostprocessorArgs": PUS_TC_ARGS,
            },
            {
                "name": "cfdp",
                "class": "org.yamcs.tctm.TcpTmDataLink",
                "stream": "cfdp_tm",
                "host": "127.0.0.1",
                "port": ports["cfdp"],
                "packetPreprocessorClassName": "org.yamcs.tctm.GenericPacketPreprocessor",
                "packetPreprocessorArgs": CFDP_TM_ARGS,
            },
        ]
    if mode != "frames":
        raise ValueError("link mode %r, expected 'packets' or 'frames'" % (mode,))

    def vc(vcid, stream, preprocessor, args):
        return {
            "vcId": vcid,
            "ocfPresent": True,
            "service": "PACKET",
            "maxPacketLength": 65542,
            "stream": stream,
            "packetPreprocessorClassName": preprocessor,
            "packetPreprocessorArgs": args,
        }

    pus_pp = "org.yamcs.pus.PusPacketPreprocessor"
    generic = "org.yamcs.tctm.GenericPacketPreprocessor"
    scid = ids.scid
    plan = ids.tm_vcs
    return [
        {
            "name": "tc_frames",
            "class": "org.yamcs.tctm.ccsds.UdpTcFrameLink",
            "host": "127.0.0.1",
            "port": ports["cltu"],
            "spacecraftId": scid,
            "maxFrameLength": 1024,
            "cltuEncoding": "BCH",
            "randomizeCltu": False,
            "errorDetection": "CRC16",
            "virtualChannels": [
                {
                    "vcId": ids.tc_vc,
                    "service": "PACKET",
                    "stream": "tc_realtime",
                    "commandPostprocessorClassName": "org.yamcs.pus.PusCommandPostprocessor",
                    "commandPostprocessorArgs": PUS_TC_ARGS,
                    "useCop1": True,
                    "clcwStream": "clcw",
                    "initialClcwWait": -1,
                }
            ],
        },
        {
            "name": "tm_frames",
            "class": "org.yamcs.tctm.ccsds.UdpTmFrameLink",
            "port": ports["tm_frames"],
            "frameType": "TM",
            "spacecraftId": scid,
            "frameLength": 256,
            "errorDetection": "CRC16",
            "clcwStream": "clcw",
            "goodFrameStream": "good_frames",
            "badFrameStream": "bad_frames",
            "virtualChannels": [
                vc(plan["realtime"], "tm_realtime", pus_pp, tm_args),
                vc(plan["playback"], "tm_dump", pus_pp, tm_args),
                vc(ids.cfdp_vc, "cfdp_tm", generic, CFDP_TM_ARGS),
                vc(plan["essential"], "tm_essential", generic, CFDP_TM_ARGS),
            ],
        },
    ]


def instance_config(
    spacecraft,
    mode,
    ports,
    mdb_file,
    ids,
    events_file="etc/events.json",
    sql_file="etc/extra_streams.sql",
):
    ground_prefix, sat_prefix = ids.ground_prefix, ids.local_prefix
    sat_entity, ground_entity = ids.cfdp_entities
    return {
        "services": [
            {"class": "org.yamcs.archive.XtceTmRecorder"},
            {"class": "org.yamcs.archive.ParameterRecorder"},
            {"class": "org.yamcs.archive.AlarmRecorder"},
            {"class": "org.yamcs.archive.EventRecorder"},
            {"class": "org.yamcs.archive.ReplayServer"},
            {"class": "org.yamcs.archive.CcsdsTmIndex", "args": {"streams": ["tm_realtime"]}},
            {
                "class": "org.yamcs.ProcessorCreatorService",
                "args": {"name": "realtime", "type": "realtime"},
            },
            {"class": "org.yamcs.archive.CommandHistoryRecorder"},
            {"class": "org.yamcs.parameterarchive.ParameterArchive"},
            {
                "class": "org.yamcs.pus.PusEventDecoder",
                "args": {
                    "eventIdParameter": "/%s/event_id" % spacecraft.mission,
                    "eventTemplateFile": events_file,
                    "realtimeStreams": ["tm_realtime"],
                },
            },
            {
                "class": "org.yamcs.cfdp.CfdpService",
                "name": "cfdp0",
                "args": {
                    "incomingBucket": "cfdpDown",
                    "allowDownloadOverwrites": True,
                    "maxPduSize": 512,
                    "sleepBetweenPdus": 1,
                    "eofAckTimeout": 2000,
                    "finAckTimeout": 2000,
                    "nakTimeout": 2000,
                    "inactivityTimeout": 10000,
                    "pendingAfterCompletion": 1000,
                    "localEntities": [
                        {"name": ground_prefix, "id": ground_entity, "bucket": "cfdpUp"}
                    ],
                    "remoteEntities": [{"name": sat_prefix, "id": sat_entity}],
                },
            },
        ],
        "dataLinks": links(mode, ports, ids),
        "mdb": [{"type": "xtce", "spec": mdb_file}],
        "streamConfig": {
            "tm": [
                {"name": "tm_realtime", "processor": "realtime"},
                {"name": "tm_dump"},
                {"name": "cfdp_tm"},
                {"name": "tm_essential"},
            ],
            "invalidTm": "invalid_tm_stream",
            "cmdHist": ["cmdhist_realtime", "cmdhist_dump"],
            "event": ["events_realtime", "events_dump"],
            "param": ["pp_realtime", "sys_param", "proc_param"],
            "parameterAlarm": ["alarms_realtime"],
            "eventAlarm": ["event_alarms_realtime"],
            "tc": [{"name": "tc_realtime", "processor": "realtime"}],
            "sqlFile": sql_file,
        },
    }


PROCESSOR = {
    "realtime": {
        "services": [
            {"class": "org.yamcs.StreamTmPacketProvider"},
            {"class": "org.yamcs.StreamTcCommandReleaser"},
            {"class": "org.yamcs.tctm.StreamParameterProvider"},
            {"class": "org.yamcs.algorithms.AlgorithmManager"},
            {"class": "org.yamcs.parameter.LocalParameterManager"},
        ],
        "config": {
            "subscribeAll": True,
            "generateEvents": True,
            "alarm": {
                "parameterCheck": True,
                "parameterServer": "enabled",
                "eventServer": "enabled",
            },
            "recordInitialValues": True,
            "recordLocalValues": True,
        },
    },
    "Archive": {
        "services": [
            {"class": "org.yamcs.tctm.ReplayService"},
            {"class": "org.yamcs.algorithms.AlgorithmManager"},
        ]
    },
    "ParameterArchive": {
        "services": [
            {"class": "org.yamcs.tctm.ReplayService"},
            {"class": "org.yamcs.algorithms.AlgorithmManager"},
        ]
    },
    "ArchiveRetrieval": {
        "config": {"subscribeContainerArchivePartitions": False},
        "services": [
            {"class": "org.yamcs.tctm.ReplayService"},
            {"class": "org.yamcs.algorithms.AlgorithmManager"},
        ],
    },
}


def cfdp_sql(apid):
    """CFDP PDUs: in from the cfdp_tm stream (space packet header removed), out as TC space
    packets of APID ``apid`` (the PUS command postprocessor fills in length and count)."""
    header = "%04X" % (0x1000 | apid) + "C0000000"
    return (
        "create stream cfdp_in as select substring(packet, 6) as pdu from cfdp_tm\n"
        "create stream cfdp_out (gentime TIMESTAMP, entityId long, seqNum int, pdu binary)\n"
        "insert into tc_realtime select gentime, 'cfdp-service' as origin, seqNum, "
        "'/yamcs/cfdp/upload' as cmdName, unhex('%s') + pdu as binary from cfdp_out\n"
    ) % header


def write_instance(
    folder,
    spacecraft,
    mode="packets",
    ports=None,
    http_port=HTTP_PORT,
    instances=None,
    ids=None,
    name=INSTANCE,
    keys=None,
    http_address="127.0.0.1",
):
    """Write a Yamcs server for ``spacecraft`` into ``folder``: one instance named ``name`` with
    ``mode`` links on ``ports``, or the ``instances`` given as {name: (mode, ports)} (one
    server, several instances). ``ids``: the mission's ids (default: the database's alone).
    With ``keys`` (an SDLS key file), the ``frames`` instances protect TC and TM with Yamcs'
    SDLS (``obsw_host.yamcs.sdls``). ``http_address``: where the web interface and API listen.
    Returns the MDB path."""
    ids = ids or spacecraft.ids
    instances = instances or {name: (mode, ports)}
    defaults = ids.ports.yamcs()
    etc = os.path.join(folder, "etc")
    mdb = os.path.join(folder, "mdb")
    os.makedirs(etc, exist_ok=True)
    os.makedirs(mdb, exist_ok=True)
    mdb_name = "%s.xml" % spacecraft.mission
    with open(os.path.join(mdb, mdb_name), "w") as f:
        f.write(generate(spacecraft))
    with open(os.path.join(etc, "events.json"), "w") as f:
        json.dump(event_templates(spacecraft), f, indent=1)
    buckets = []
    files = {}
    for name, (mode_, ports_) in instances.items():
        config = instance_config(
            spacecraft, mode_, dict(defaults, **(ports_ or {})), "mdb/" + mdb_name, ids
        )
        files["yamcs.%s.yaml" % name] = _instance_yaml(folder, name, config, mode_, keys, buckets)
    files.update(_server_files(http_port, list(instances), buckets, http_address))
    files["extra_streams.sql"] = cfdp_sql(ids.apid("cfdp"))
    _write_etc(etc, files)
    return os.path.join(mdb, mdb_name)


def _instance_yaml(folder, name, config, mode, keys, buckets):
    """Instance ``name``'s yaml text, its CFDP buckets made and added to ``buckets``."""
    for way in ("up", "down"):
        path = os.path.join("files", name, way)
        os.makedirs(os.path.join(folder, path), exist_ok=True)
        buckets.append({"name": "%s_%s" % (name, way), "path": path})
    if keys is not None and mode == "frames":
        from obsw_host.yamcs.sdls import secure_links

        secure_links(config["dataLinks"], keys, os.path.join(folder, "etc"))
    cfdp = config["services"][-1]["args"]
    cfdp["incomingBucket"] = name + "_down"
    cfdp["localEntities"][0]["bucket"] = name + "_down"  # where files to it land
    return _yaml(config)


def _server_files(http_port, instances, buckets, address="127.0.0.1"):
    server = {
        "services": [
            {
                "class": "org.yamcs.http.HttpServer",
                "args": {"address": address, "port": http_port},
            }
        ],
        "dataDir": "data",
        "instances": instances,
        "secretKey": "obsw-local-only",
        "buckets": buckets,
    }
    return {"yamcs.yaml": _yaml(server), "processor.yaml": _yaml(PROCESSOR)}


def _write_etc(etc, files):
    for name, text in files.items():
        with open(os.path.join(etc, name), "w") as f:
            f.write(text + "\n")


class Member:
    """One spacecraft of a fleet: its instance ``name``, database ``spacecraft``, link ``mode``,
    Yamcs' link ``ports`` and mission ``ids``."""

    def __init__(self, name, spacecraft, mode, ports, ids):
        self.name = name
        self.spacecraft = spacecraft
        self.mode = mode
        self.ports = ports
        self.ids = ids


def write_fleet(folder, members, http_port=HTTP_PORT, http_address="127.0.0.1"):
    """Write one Yamcs server operating several spacecraft into ``folder``: an instance per
    ``Member``, each with its own mission database (``mdb/NAME.xml``), event templates
    (``etc/events.NAME.json``), CFDP streams (``etc/extra_streams.NAME.sql``), buckets and
    links. ``http_address``: where the web interface and API listen (loopback unless the
    operators reach Yamcs from other machines). Returns {instance name: MDB path}."""
    etc = os.path.join(folder, "etc")
    mdb = os.path.join(folder, "mdb")
    os.makedirs(etc, exist_ok=True)
    os.makedirs(mdb, exist_ok=True)
    buckets, files, paths = [], {}, {}
    for m in members:
        mdb_file = "mdb/%s.xml" % m.name
        events_file = "etc/events.%s.json" % m.name
        sql_file = "etc/extra_streams.%s.sql" % m.name
        with open(os.path.join(folder, mdb_file), "w") as f:
            f.write(generate(m.spacecraft))
        with open(os.path.join(folder, events_file), "w") as f:
            json.dump(event_templates(m.spacecraft), f, indent=1)
        ports = dict(m.ids.ports.yamcs(), **(m.ports or {}))
        config = instance_config(
            m.spacecraft, m.mode, ports, mdb_file, m.ids, events_file, sql_file
        )
        files["yamcs.%s.yaml" % m.name] = _instance_yaml(folder, m.name, config, m.mode, None,
                                                          buckets)  # fmt: skip
        files[os.path.basename(sql_file)] = cfdp_sql(m.ids.apid("cfdp"))
        paths[m.name] = os.path.join(folder, mdb_file)
    files.update(_server_files(http_port, [m.name for m in members], buckets, http_address))
    _write_etc(etc, files)
    return paths
