"""The ground application process on the host: service users over UDP, and a scripting API.

    from obsw_host.pus.ground import Ground
    with Ground(sdb) as ground:               # talks to 127.0.0.1:base + the sdb's 'pus' APID
        tx = ground.ping()                    # a Transaction: tx.ok, tx.reply, tx.verification()
        hk = ground.housekeeping(1)           # {'sid': 1, 'values': {'SolarPanel.angle': 0.0, ..}}
        ground.set_parameter("SolarPanel.speed", 7.5)
        ground.get_parameters("SolarPanel.speed")   # {'SolarPanel.speed': 7.5}
        ground.perform("SolarPanel.set_angle", angle=15.0)          # service 8
        ground.call_service("mtq", "dipole", x=0.1, y=0.0, z=0.0)   # a mission service
        act = ground.function_request("SolarPanel.set_angle", angle=20.0)
        ground.schedule_in(5.0, act)          # service 11; act.ok once it has run on board
        ground.add_limit_monitor(1, "SolarPanel.speed", 0.5, 10.0,
                                 high_event="monitoring.speed_high")   # service 12
        ground.add_action("monitoring.speed_high",
                          ground.parameter_request({"SolarPanel.speed": 5.0}))  # 19

Each call sends its TC and waits (driving the socket) until the completion report, a
failure report or the timeout; every packet in either direction can be shown on ``log`` and
written to a session log (``session=SessionLog(path)``, ``obsw_host.pus.monitor``). The on-board
process sends TM to every ground that sent it a TC or ``subscribe()``d, so several grounds see
the same TM (``obsw_host.pus.tm_fanout``); ``close()`` unsubscribes.
"""

import select
import socket

from obsw.il.clock import REAL_CLOCK
from obsw.pus.config import DEFAULT, from_sdb
from obsw.pus.services.mission import MissionServiceUser
from obsw.pus.services.s03_housekeeping import HousekeepingUser
from obsw.pus.services.s05_events import EventUser
from obsw.pus.services.s08_functions import FunctionUser, functions
from obsw.pus.services.s09_time import TimeUser
from obsw.pus.services.s11_scheduling import TimeSchedulingUser
from obsw.pus.services.s12_functional_user import FunctionalMonitoringUser, functional_check
from obsw.pus.services.s12_user import limit_check
from obsw.pus.services.s17_test import ServiceTestUser
from obsw.pus.services.s19_event_action import EventActionUser
from obsw.pus.services.s20_parameters import ParameterUser
from obsw.pus.services.s21_sequencing import RequestSequencingUser
from obsw.pus.services.s22_position_scheduling import PositionSchedulingUser
from obsw.pus.user import UserProcess

from obsw_host.mission.ids import MissionIds
from obsw_host.mission.ports import app_port
from obsw_host.net import DEFAULT_HOST
from obsw_host.pus import text
from obsw_host.pus.tai import tai_now
from obsw_host.pus.tm_fanout import SUBSCRIBE, UNSUBSCRIBE


class PusTimeout(TimeoutError):
    """No completion (or failure) report within the timeout; ``transaction`` has the rest."""

    def __init__(self, tx, timeout):
        super().__init__(
            "TC[%d,%d] seq %d: no completion report within %ss (reports so far: %s)"
            % (tx.tc.service, tx.tc.subtype, tx.tc.seq_count, timeout, tx.verification())
        )
        self.transaction = tx


def _address(address):
    """(IP, port) of a (host, port) pair: what ``recvfrom`` gives for datagrams from it."""
    host, port = address[0], int(address[1])
    try:
        host = socket.getaddrinfo(host, port, socket.AF_INET, socket.SOCK_DGRAM)[0][4][0]
    except (OSError, IndexError):
        pass
    return (host, port)


class Ground:
    """Service users of the ground segment on one UDP socket (see the module text)."""

    def __init__(
        self,
        sdb=None,
        *,
        apid=None,
        target=None,
        host=DEFAULT_HOST,
        timeout=2.0,
        source_id=None,
        log=None,
        session=None,
        config=None,
        accept=(),
    ):
        self.sdb = sdb
        self.session = session  # a SessionLog, or None
        if apid is None and sdb is None:
            raise ValueError("Ground: give a spacecraft database or the on-board APID")
        self.apid = apid if apid is not None else sdb.apid("pus")
        self.target = target or (host, app_port(self.apid))
        self.timeout = timeout
        self.log = log  # callable(str) shown every packet, or None
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.bind((self.target[0], 0))
        # TM is taken from the on-board process's address only (and from ``accept``, the
        # addresses of other TM sources the operator named): a datagram from anywhere else
        # is counted in ``foreign`` and dropped, never decoded
        self.accept = {_address(self.target)} | {_address(a) for a in accept}
        self.foreign = 0
        if source_id is None:  # the database's (pus.source_id or apids.ground), else 0; the
            # ground tools pass MissionIds.source_id, which refuses a database without one
            ids = MissionIds(sdb, None) if sdb is not None else None
            source_id = ids.source_id if ids is not None and ids.has_source_id() else 0
        if config is None:  # the database's packet layout
            config = from_sdb(sdb) if sdb is not None else DEFAULT
        self.config = config
        self.proc = UserProcess(self._send, REAL_CLOCK, source_id=source_id, config=config)
        self.proc.listeners.append(self._show)
        self.received = []  # (tm, decoded) of TM no request asked for (events, periodic HK)
        self.keep_unsolicited = 1000
        reg = self.proc.register
        self.test = reg(ServiceTestUser())
        self.time = reg(TimeUser())
        self.schedule = reg(TimeSchedulingUser())
        self.position = reg(PositionSchedulingUser())
        self.event_action = reg(EventActionUser())
        self.sequencing = reg(RequestSequencingUser())
        if sdb is not None:
            types = lambda pid: sdb.parameter(pid).type  # noqa: E731
            names = lambda pid: sdb.parameter(pid).qualified  # noqa: E731
            ids = lambda key: sdb.parameter(key).id  # noqa: E731
            self.hk = reg(HousekeepingUser(types, names, sdb.housekeeping))
            self.events = reg(EventUser(sdb.event))
            self.params = reg(ParameterUser(types, names, ids, sdb.parameter))
            self.functions = reg(FunctionUser(functions(sdb)))
            self.monitoring = reg(FunctionalMonitoringUser(types, ids))
        else:
            self.hk = self.events = self.params = self.functions = self.monitoring = None
        self.mission_services = {}  # mission service name -> its user (types 128..255)
        for definition in sdb.services.values() if sdb is not None else ():
            self.mission_services[definition.name] = reg(MissionServiceUser(definition))

    # -------------------------------------------------------------------------- I/O

    def _send(self, raw):
        self.sock.sendto(raw, self.target)
        if self.session is not None:
            from obsw.pus.tc import PusTc

            self.session.write("TC", raw, line=text.tc_line(PusTc.unpack(raw, self.config)))

    def subscribe(self):
        """Ask the on-board process for its TM without sending a TC (repeat within its
        linger time, a minute by default, to keep receiving)."""
        self.sock.sendto(SUBSCRIBE, self.target)

    def _show(self, tm, decoded, tx):
        if tx is None and tm.service != 1:
            self.received.append((tm, decoded))
            if len(self.received) > self.keep_unsolicited:
                del self.received[0]
        if self.log is not None:
            self.log(text.tm_line(tm, decoded))

    def send(self, apid, service, subtype, data=b"", expect=None, ack=None):
        """Send a raw TC through the user process; returns its Transaction."""
        from obsw.pus.packets import ACK_ALL

        tx = self.proc.send(apid, service, subtype, data, expect, ACK_ALL if ack is None else ack)
        if self.log is not None:
            self.log(text.tc_line(tx.tc))
        return tx

    def poll(self, timeout=0.0):
        """Receive and decode TM for up to ``timeout`` seconds; returns how many came."""
        n = 0
        wait = timeout
        while True:
            r, _, _ = select.select([self.sock], [], [], wait)
            if not r:
                return n
            try:
                data, sender = self.sock.recvfrom(65536)
            except OSError:
                return n
            if sender not in self.accept:
                self.foreign += 1
                wait = 0
                continue
            result = self.proc.receive(data)
            if self.session is not None:
                decoded = result[1] if result else None
                line = text.tm_line(result[0], decoded) if result else "malformed"
                self.session.write("TM", data, decoded, line)
            n += 1
            wait = 0

    def wait(self, tx, timeout=None, raise_on_timeout=True):
        """Drive the socket until ``tx`` is done; returns ``tx``."""
        timeout = self.timeout if timeout is None else timeout
        deadline = REAL_CLOCK.now() + timeout
        while not tx.done:
            left = deadline - REAL_CLOCK.now()
            if left <= 0:
                if raise_on_timeout:
                    raise PusTimeout(tx, timeout)
                return tx
            self.poll(left)
        return tx

    def issue(self, tx, timeout=None):
        if self.log is not None:
            self.log(text.tc_line(tx.tc))
        return self.wait(tx, timeout)

    # -------------------------------------------------------------------------- scripting

    def ping(self, apid=None, timeout=None):
        """TC[17,1] are-you-alive; returns the Transaction (``tx.reply`` is TM[17,2])."""
        return self.issue(self.test.ping(self.apid if apid is None else apid), timeout)

    def connection_test(self, target, apid=None, timeout=None):
        """TC[17,3]: ask the process whether on-board process ``target`` answers."""
        return self.issue(
            self.test.connection_test(self.apid if apid is None else apid, target), timeout
        )

    def housekeeping(self, sid, apid=None, timeout=None, kind="hk"):
        """TC[3,27] (``kind="diag"``: TC[3,28]) one-shot report of structure ``sid``;
        ``tx.reply['values']`` by name. A structure this ground does not know yet (one created
        by another client or session) is asked for first (TC[3,9] / TC[3,11])."""
        self.learn_structure(sid, apid, timeout, kind)
        return self.issue(self.hk.one_shot(self._apid(apid), [sid], kind), timeout)

    def learn_structure(self, sid, apid=None, timeout=None, kind="hk"):
        """Ask for structure ``sid``'s definition unless this ground knows it; True if known."""
        known = self.hk.structures if kind == "hk" else self.hk.diagnostics
        if sid not in known:
            self.wait(self.hk.report_structures(self._apid(apid), [sid], kind), timeout)
        return sid in known

    def hk_structures(self, sids, apid=None, timeout=None):
        """TC[3,9]; ``tx.replies`` holds one TM[3,10] per structure."""
        return self.issue(self.hk.report_structures(self._apid(apid), sids), timeout)

    def hk_properties(self, sids, apid=None, timeout=None):
        """TC[3,33]; ``tx.reply['items']`` gives each structure's status and interval."""
        return self.issue(self.hk.report_properties(self._apid(apid), sids), timeout)

    def create_hk(self, sid, interval, parameters, apid=None, timeout=None):
        """TC[3,1]: a new structure of parameters (names or IDs), disabled."""
        pids = [self.sdb.parameter(p).id for p in parameters]
        return self.issue(self.hk.create(self._apid(apid), sid, interval, pids), timeout)

    def delete_hk(self, sids, apid=None, timeout=None):
        return self.issue(self.hk.delete(self._apid(apid), sids), timeout)

    def enable_hk(self, sids, apid=None, timeout=None):
        return self.issue(self.hk.enable(self._apid(apid), sids), timeout)

    def disable_hk(self, sids, apid=None, timeout=None):
        return self.issue(self.hk.disable(self._apid(apid), sids), timeout)

    def set_hk_interval(self, sid, interval, apid=None, timeout=None):
        """TC[3,31]: ``interval`` in cycles of the on-board activity loop."""
        return self.issue(self.hk.modify_interval(self._apid(apid), {sid: interval}), timeout)

    def get_parameters(self, *keys, apid=None, timeout=None):
        """TC[20,1]; ``tx.reply['values']`` maps names to values."""
        return self.issue(self.params.report(self._apid(apid), keys), timeout)

    def set_parameter(self, key, value, apid=None, timeout=None, raw=False):
        """TC[20,3] for one parameter (name or ID)."""
        return self.set_parameters({key: value}, apid, timeout, raw)

    def set_parameters(self, values, apid=None, timeout=None, raw=False):
        """TC[20,3]: engineering values (labels, calibrated numbers; ``raw``: raw values),
        refused here (``RangeError``) when outside a parameter's range."""
        return self.issue(self.params.set(self._apid(apid), values, raw), timeout)

    def _event_ids(self, keys):
        return [self.sdb.event(k).id for k in keys]

    def enable_events(self, keys, apid=None, timeout=None):
        return self.issue(self.events.enable(self._apid(apid), self._event_ids(keys)), timeout)

    def disable_events(self, keys, apid=None, timeout=None):
        return self.issue(self.events.disable(self._apid(apid), self._event_ids(keys)), timeout)

    def disabled_events(self, apid=None, timeout=None):
        """TC[5,7]; ``tx.reply['ids']`` lists the disabled event IDs."""
        return self.issue(self.events.report_disabled(self._apid(apid)), timeout)

    def set_time_rate(self, exponent, apid=None, timeout=None):
        """TC[9,1]: a time report every 2 ** exponent seconds."""
        return self.issue(self.time.set_rate(self._apid(apid), exponent), timeout)

    # -------------------------------------------------------------------------- automation

    def request(self, service, subtype, data=b"", apid=None):
        """A TC for on-board use (scheduled, sequenced, an action), not sent: its
        Transaction, open, so its reports are matched whenever it runs on board."""
        return self.schedule.embed(self._apid(apid), service, subtype, data)[1]

    def function_request(self, key, apid=None, **arguments):
        """A TC[8,1] for on-board use (see ``request``)."""
        return self.request(8, 1, self.functions.pack(key, arguments), apid)

    def parameter_request(self, values, apid=None):
        """A TC[20,3] for on-board use (see ``request``)."""
        items = self.params.raw_items(values)
        return self.request(20, 3, self.params.layout.pack({"items": items}), apid)

    def mission_service(self, key):
        """The user of mission service ``key`` (its name or type)."""
        definition = self.sdb.service(key) if self.sdb is not None else None
        if definition is None:
            raise KeyError("no mission service %r: the ground has no database" % (key,))
        return self.mission_services[definition.name]

    def service_request(self, service, request, apid=None, **arguments):
        """A request of a mission service for on-board use (see ``request``); its arguments
        are checked against their types and ranges (MissionArgumentError)."""
        user = self.mission_service(service)
        r = user.definition.request(request)
        return self.request(r.service.type, r.subtype, user.pack(request, arguments), apid)

    def call_service(self, service, request, apid=None, timeout=None, **arguments):
        """Send request ``request`` of mission service ``service`` (names or numbers) with
        named arguments, checked first; ``tx.reply`` is its report decoded by name."""
        user = self.mission_service(service)
        return self.issue(user.send(self._apid(apid), request, arguments), timeout)

    def perform(self, key, apid=None, timeout=None, **arguments):
        """TC[8,1]: perform function ``key`` (ID or name) with named arguments."""
        return self.issue(self.functions.perform(self._apid(apid), key, arguments), timeout)

    def schedule_at(self, at, request, subschedule=0, group=0, apid=None, timeout=None):
        """TC[11,4]: release ``request`` (a Transaction of ``request``) at on-board TAI ``at``."""
        items = [(at, request, subschedule, group)]
        return self.issue(self.schedule.insert(self._apid(apid), items), timeout)

    def schedule_in(self, seconds, request, **options):
        """TC[11,4] releasing ``request`` ``seconds`` from now (the ground's clock)."""
        return self.schedule_at(tai_now() + seconds, request, **options)

    def scheduled(self, apid=None, timeout=None):
        """TC[11,16]; ``tx.reply['activities']`` lists the time-based schedule."""
        return self.issue(self.schedule.detail_all(self._apid(apid)), timeout)

    def schedule_summary(self, apid=None, timeout=None):
        """TC[11,17]; ``tx.reply['activities']`` names the activities by request ID."""
        return self.issue(self.schedule.summary_all(self._apid(apid)), timeout)

    def shift_schedule(self, seconds, ids=None, apid=None, timeout=None):
        """TC[11,15] (all) or TC[11,7] (``ids``: request IDs or transactions)."""
        a = self._apid(apid)
        if ids is None:
            return self.issue(self.schedule.shift_all(a, seconds), timeout)
        return self.issue(self.schedule.shift(a, seconds, ids), timeout)

    def unschedule(self, ids, apid=None, timeout=None):
        """TC[11,5]: delete activities by request ID (or transaction)."""
        return self.issue(self.schedule.delete(self._apid(apid), ids), timeout)

    def enable_schedule(self, enabled=True, apid=None, timeout=None):
        """TC[11,1] or TC[11,2]."""
        user = self.schedule
        tx = user.enable(self._apid(apid)) if enabled else user.disable(self._apid(apid))
        return self.issue(tx, timeout)

    def reset_schedule(self, apid=None, timeout=None):
        return self.issue(self.schedule.reset(self._apid(apid)), timeout)

    def schedule_at_position(self, position, request, apid=None, timeout=None):
        """TC[22,4]: release ``request`` when the position parameter reaches ``position``."""
        return self.issue(self.position.insert(self._apid(apid), [(position, request)]), timeout)

    def position_scheduled(self, apid=None, timeout=None):
        """TC[22,16]; ``tx.reply['activities']`` lists the position-based schedule."""
        return self.issue(self.position.detail_all(self._apid(apid)), timeout)

    def add_limit_monitor(
        self,
        pmon,
        parameter,
        low,
        high,
        low_event=0,
        high_event=0,
        apid=None,
        timeout=None,
        raw=False,
        **options,
    ):
        """TC[12,5] for one limit check (events by name or ID; 0: none), then TC[12,1].
        ``low`` and ``high`` are engineering values (``raw``: raw ones), sent as raw limits
        (``obsw.pus.calibration.Values.raw_limits``)."""
        low_event, high_event = self._event_id(low_event), self._event_id(high_event)
        low, high, swapped = self.sdb.parameter(parameter).raw_limits(low, high, raw)
        if swapped:  # a falling calibration: the low raw limit is the high engineering one
            low_event, high_event = high_event, low_event
        d = limit_check(pmon, parameter, low, high, low_event, high_event, **options)
        tx = self.issue(self.monitoring.add(self._apid(apid), [d]), timeout)
        if not tx.ok:
            return tx
        return self.enable_monitors([pmon], apid=apid, timeout=timeout)

    def add_monitors(self, definitions, apid=None, timeout=None):
        """TC[12,5] for definitions built with ``obsw.pus.services.s12_user``."""
        return self.issue(self.monitoring.add(self._apid(apid), definitions), timeout)

    def enable_monitors(self, ids, enabled=True, apid=None, timeout=None):
        """TC[12,1] or TC[12,2]."""
        user = self.monitoring
        fn = user.enable if enabled else user.disable
        return self.issue(fn(self._apid(apid), ids), timeout)

    def delete_monitors(self, ids, apid=None, timeout=None):
        return self.issue(self.monitoring.delete(self._apid(apid), ids), timeout)

    def monitors(self, ids=(), apid=None, timeout=None):
        """TC[12,8]; ``tx.reply['items']`` are the definitions (all if no ``ids``)."""
        return self.issue(self.monitoring.report_definitions(self._apid(apid), ids), timeout)

    def out_of_limits(self, apid=None, timeout=None):
        """TC[12,10]; ``tx.reply['items']`` are the parameters now out of limits."""
        return self.issue(self.monitoring.report_out_of_limits(self._apid(apid)), timeout)

    # -------------------------------------------------------------------------- functional

    def add_functional_monitor(self, fmon, pmons, failing=1, event=0, apid=None, timeout=None):
        """TC[12,23]: FMON ``fmon`` fails when ``failing`` of ``pmons`` are out of limits and
        raises ``event`` (name or ID); new FMONs are disabled."""
        d = functional_check(fmon, pmons, failing, self._event_id(event))
        return self.issue(self.monitoring.add_functional(self._apid(apid), [d]), timeout)

    def functional_monitors(self, apid=None, timeout=None, ids=()):
        """TC[12,25]; ``tx.reply['functional']`` are the FMON definitions (all if no ids)."""
        return self.issue(self.monitoring.report_functional(self._apid(apid), ids), timeout)

    def functional_status(self, apid=None, timeout=None):
        """TC[12,27]; ``tx.reply['functional']`` gives each FMON's statuses."""
        return self.issue(self.monitoring.report_functional_status(self._apid(apid)), timeout)

    def functional_request(self, action, ids=(), apid=None, timeout=None):
        """TC[12,17]-[12,24] by name: enable-function, disable-function (no IDs), enable,
        disable, protect, unprotect, delete (FMON IDs)."""
        user = self.monitoring
        a = self._apid(apid)
        if action in ("enable-function", "disable-function"):
            fn = getattr(user, action.replace("-function", "") + "_functional_function")
            return self.issue(fn(a), timeout)
        fn = getattr(user, action + "_functional", None)
        if fn is None or action in ("add", "report"):
            raise ValueError("functional monitoring action %r unknown" % action)
        return self.issue(fn(a, list(ids)), timeout)

    def parameter_definitions(self, keys=(), apid=None, timeout=None):
        """TC[20,6]; ``tx.reply['definitions']`` says where each parameter lives."""
        return self.issue(self.params.report_definitions(self._apid(apid), keys), timeout)

    def define_parameters(self, items, object_memory=False, apid=None, timeout=None):
        """TC[20,4]: ``items`` are (parameter, memory ID, absolute address); or TC[20,5]
        (``object_memory``): (parameter, memory ID, object ID, offset in the object)."""
        user = self.params
        fn = user.change_object_definitions if object_memory else user.change_raw_definitions
        return self.issue(fn(self._apid(apid), items), timeout)

    def _event_id(self, key):
        return key if isinstance(key, int) else self.sdb.event(key).id

    def add_action(self, event, request, apid=None, timeout=None, enable=True):
        """TC[19,1] running ``request`` when ``event`` (name or ID) occurs, then TC[19,4]."""
        a = self._apid(apid)
        key = (a, self._event_id(event))
        tx = self.issue(self.event_action.add(a, [key + (request,)]), timeout)
        if not tx.ok or not enable:
            return tx
        return self.issue(self.event_action.enable(a, [key]), timeout)

    def enable_actions(self, events, enabled=True, apid=None, timeout=None):
        """TC[19,4] or TC[19,5] for the actions of ``events`` of this process."""
        a = self._apid(apid)
        keys = [(a, self._event_id(e)) for e in events]
        user = self.event_action
        fn = user.enable if enabled else user.disable
        return self.issue(fn(a, keys), timeout)

    def delete_actions(self, events, apid=None, timeout=None):
        a = self._apid(apid)
        keys = [(a, self._event_id(e)) for e in events]
        return self.issue(self.event_action.delete(a, keys), timeout)

    def actions(self, apid=None, timeout=None):
        """TC[19,10]; ``tx.reply['items']`` are every event-action definition."""
        return self.issue(self.event_action.report_definitions(self._apid(apid)), timeout)

    def load_sequence(self, name, items, apid=None, timeout=None):
        """TC[21,1]: ``items`` are (request, delay in seconds) pairs."""
        return self.issue(self.sequencing.load(self._apid(apid), name, items), timeout)

    def activate_sequence(self, name, apid=None, timeout=None):
        return self.issue(self.sequencing.activate(self._apid(apid), name), timeout)

    def abort_sequence(self, name, apid=None, timeout=None):
        return self.issue(self.sequencing.abort(self._apid(apid), name), timeout)

    def unload_sequence(self, name, apid=None, timeout=None):
        return self.issue(self.sequencing.unload(self._apid(apid), name), timeout)

    def sequences(self, apid=None, timeout=None):
        """TC[21,6]; ``tx.reply['items']`` gives each loaded sequence's status."""
        return self.issue(self.sequencing.report_status(self._apid(apid)), timeout)

    def sequence_content(self, name, apid=None, timeout=None):
        return self.issue(self.sequencing.report_content(self._apid(apid), name), timeout)

    def wait_for(self, service, subtype, timeout=None, since=0):
        """The next TM[service, subtype] no request asked for (an event, a periodic report),
        as ``(tm, decoded)``, or None after ``timeout`` seconds. ``since`` skips the first
        entries of ``received`` (pass ``len(ground.received)`` taken before the trigger)."""
        timeout = self.timeout if timeout is None else timeout
        deadline = REAL_CLOCK.now() + timeout
        i = since
        while True:
            while i < len(self.received):
                tm, decoded = self.received[i]
                i += 1
                if tm.service == service and tm.subtype == subtype:
                    return tm, decoded
            left = deadline - REAL_CLOCK.now()
            if left <= 0:
                return None
            self.poll(min(left, 0.05))

    def _apid(self, apid):
        return self.apid if apid is None else apid

    def close(self):
        try:
            self.sock.sendto(UNSUBSCRIBE, self.target)
        except OSError:
            pass  # best effort: the on-board process drops a silent client anyway
        self.sock.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
