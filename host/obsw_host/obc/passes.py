"""Contact awareness in the OBC's PUS process: the pass table, the stores' dump, CFDP held.

The ``Passes`` component (interface ``PASSES``) lives in the PUS process beside service 15's
packet stores and the CFDP entity. It keeps a ``Contact`` (``obsw.frames.contact``) fed

- from the link: every TC the process receives came through a TC frame the frame processor
  accepted, so each one is the link heard (``heard``); out of the table's windows the OBC is
  in contact for ``hold`` seconds after the last one;
- from the onboard pass table the ground uplinks with TC[8,1] ``Passes.load`` (``table``:
  the layout of ``pack_table``), so the dump starts at AOS before the first TC.

With ``contact.stores`` set in the mission file (the stores dumped, highest priority first),
a TM that one of those stores keeps does not go out in real time: it waits in the store, and
in contact ``StoreForward`` (``obsw.frames.downlink``) hands it to the store's virtual channel
in storage order, by priority, at ``share`` of the downlink rate and only what the pass can
still carry; where it stands in each store is kept in the state folder (``passes.json``), so
a restarted process goes on after the last packet it sent, and so is the pass table last
loaded (``passes.json.table``), so it knows its passes at once. Each cycle that sent packets of
a store raises the event ``passes.dumped`` (store, first and last storage sequence number,
count); the ground acknowledges what it has
with TC[8,1] ``Passes.acknowledge`` (store, seq: deletes through it, the room is free again)
and asks again for what it lacks with ``Passes.resend`` (store, first, last). The forwarder's
pointer never goes back, so nothing leaves twice unless the ground asks for it. The CFDP
entity of the same process is held across passes (``obsw.cfdp.contact.PassHold``): suspended
at LOS, its timers frozen, resumed at AOS; its file data has the dump's part of the downlink
(``spare``) when the stores have nothing waiting, and none while they do. Without
``contact.stores`` the TM stays in real time and CFDP is not held (a ground always in view);
the pass table still loads.

Pass table layout (``table``, octets, big-endian): 8 octets a pass, at most ``MAX_WINDOWS``
(64) passes, ordered, disjoint: AOS then LOS, each uint32 whole seconds of onboard time (TAI
seconds since 1958-01-01, the PUS epoch). An empty table clears it. A table of another
length, a pass whose AOS is not before its LOS, passes out of order or overlapping, or too
many passes are refused (completion failure of the TC[8,1], ``BAD_TABLE`` with the reason);
the table in force stays.
"""

import time

from obsw.frames.contact import AOS, MAX_WINDOWS, Contact, PassTableError
from obsw.frames.downlink import StoreForward
from obsw.il.interface import DATA, INFO, Attribute, Event, Interface, Operation

PASSES = Interface(
    "Passes",
    0x7E50,
    [
        Attribute("in_contact", 1, DATA, type="bool", description="contact with the ground"),
        Attribute("passes", 2, DATA, type="u16", description="passes in the table to come"),
        Attribute("aos_count", 3, DATA, type="u32", description="contacts begun"),
        Attribute("backlog", 4, DATA, type="u32", unit="octet", description="stored, unsent"),
        Operation("load", 5, ("table",), description="replace the pass table"),
        Operation("acknowledge", 6, ("store", "seq"), description="the ground has these"),
        Operation("resend", 7, ("store", "first", "last"), description="send these again"),
        Event("aos", 8, INFO, fields=("passes",)),
        Event("los", 9, INFO, fields=("backlog",)),
    ],
    description="contact, the pass table and the stores' dump (obsw_host.obc.passes)",
)
PASS_OCTETS = 8


def pack_table(windows):
    """The ``table`` argument of ``Passes.load`` for ``[(aos, los), ..]`` onboard seconds."""
    out = bytearray()
    for aos, los in windows:
        a, b = int(-(-aos // 1)), int(los)  # whole seconds inside it: never longer
        if not 0 <= a < b < 1 << 32:
            raise PassTableError("pass %r..%r: no whole second inside it, or outside uint32 "
                                 "onboard seconds" % (aos, los))  # fmt: skip
        out += a.to_bytes(4, "big") + b.to_bytes(4, "big")
    return bytes(out)


def unpack_table(table):
    """``[(aos, los), ..]`` from the octets of a table; ``PassTableError`` if malformed."""
    table = bytes(table)
    if len(table) % PASS_OCTETS:
        raise PassTableError(
            "table of %d octets; expected %d octets a pass" % (len(table), PASS_OCTETS)
        )
    if len(table) // PASS_OCTETS > MAX_WINDOWS:
        raise PassTableError(
            "%d passes; expected at most %d" % (len(table) // PASS_OCTETS, MAX_WINDOWS)
        )
    out = []
    for i in range(0, len(table), PASS_OCTETS):
        aos = int.from_bytes(table[i : i + 4], "big")
        los = int.from_bytes(table[i + 4 : i + 8], "big")
        out.append((aos, los))
    return out


class Passes:
    """The component (see the module text). ``storage`` is service 15 (or None), ``play``
    sends a stored packet on a virtual channel, ``now`` is onboard time, ``event(name,
    values)`` raises a database event; ``entity`` is the process's CFDP entity (or None)."""

    def __init__(self, storage, play, now, event, *, stores=(), hold=10.0, bps=9600.0,
                 share=0.8, entity=None, clock=time.monotonic, path=None):  # fmt: skip
        from obsw.cfdp.contact import PassHold

        self.storage = storage
        self.play = play
        self.now = now
        self.event = event
        self.order = list(stores)
        self.enabled = bool(self.order) and storage is not None
        self.contact = Contact(hold=hold)
        self.forward = StoreForward([], self.contact, bps)
        self.cycle_octets = bps * share / 8  # per second: the dump's share of the link
        self.hold = PassHold(entity) if entity is not None and self.enabled else None
        self.clock = clock
        self.path = path  # where the forwarder's pointers are kept across restarts
        self.saved = self._restore()
        self.il = None
        self.in_contact = False
        self.passes = 0
        self.aos_count = 0
        self.backlog = 0
        self.dumped = 0
        # octets/s the radio has for files (the CFDP entity's file data): the dump's share
        # when the stores have nothing waiting, none while they do (they come first)
        self.spare = self.cycle_octets
        self._last = None
        self._credit = 0.0
        self._restore_table()

    def _restore(self):
        import json

        if self.path is None:
            return {}
        try:
            with open(self.path) as f:
                return {int(k): int(v) for k, v in json.load(f).items()}
        except (OSError, ValueError, TypeError, AttributeError):
            return {}  # none yet, or unreadable: from each store's oldest packet

    def _save(self):
        import json
        import os

        if self.path is None:
            return
        part = self.path + ".part"
        try:
            with open(part, "w") as f:
                json.dump({str(k): v for k, v in self.forward.next_seq.items()}, f)
            os.replace(part, self.path)
        except OSError:
            pass  # a full disk: after a restart the unacknowledged packets go again

    def _table_path(self):
        return None if self.path is None else self.path + ".table"

    def _restore_table(self):
        """The pass table last loaded (kept beside the pointers): a restarted process knows
        its passes without waiting for the ground to load them again."""
        path = self._table_path()
        if path is None:
            return
        try:
            with open(path, "rb") as f:
                self.contact.load(unpack_table(f.read()))
        except (OSError, ValueError, PassTableError):
            return  # none yet, or unreadable: the ground loads it again
        self.passes = len(self.contact.windows)

    def _save_table(self, table):
        import os

        path = self._table_path()
        if path is None:
            return
        try:
            with open(path + ".part", "wb") as f:
                f.write(bytes(table))
            os.replace(path + ".part", path)
        except OSError:
            pass  # a full disk: after a restart the ground loads the table again

    def il_bind(self, provider):
        self.il = provider

    def _set(self, name, value):
        if getattr(self, name) == value:
            return
        if self.il is not None:
            self.il.update(name, value)
        else:
            setattr(self, name, value)

    # ---------------------------------------------------------------------- the ground's TCs

    def load(self, table):
        from obsw.il.errors import ComponentError

        try:
            self.contact.load(unpack_table(table))
        except PassTableError as e:
            raise ComponentError("BAD_TABLE", str(e)) from None
        self._save_table(table)
        self._set("passes", len(self.contact.windows))
        return True

    def acknowledge(self, store, seq):
        from obsw.il.errors import ComponentError

        self._sync()
        try:
            self.forward.acknowledge(int(store), int(seq))
        except KeyError as e:
            raise ComponentError("UNKNOWN_STORE", str(e.args[0])) from None
        return True

    def resend(self, store, first, last):
        from obsw.il.errors import ComponentError

        self._sync()
        try:
            if not self.forward.resend(int(store), int(first), int(last)):
                raise ComponentError("BUSY", "resend queue full; ask again")
        except KeyError as e:
            raise ComponentError("UNKNOWN_STORE", str(e.args[0])) from None
        return True

    # ---------------------------------------------------------------------- on board

    def heard(self):
        """A TC arrived: the link is there."""
        self.contact.heard(self.now())

    def realtime(self, h):
        """The TM pipeline's filter: False for a TM a dumped store keeps (it waits there)."""
        if not self.enabled:
            return True
        stores, controls = self.storage.stores, self.storage.controls
        for sid in self.order:
            st = stores.get(sid)
            if st is not None and st.enabled and controls[sid].selects(h):
                return False
        return True

    def _sync(self):
        """The forwarded stores as service 15 has them now (created, deleted, restored)."""
        if self.storage is None:
            return
        stores = [self.storage.stores[s] for s in self.order if s in self.storage.stores]
        fw = self.forward
        if [s.id for s in stores] != [s.id for s in fw.stores]:
            fw.stores = stores
            for st in stores:
                if st.id not in fw.next_seq:  # where it stood, else the oldest packet kept
                    oldest = st.packets[0][0] if st.packets else st.next_seq
                    fw.next_seq[st.id] = max(oldest, min(self.saved.get(st.id, 0),
                                                         st.next_seq))  # fmt: skip
        else:
            fw.stores = stores  # a store recreated under its id is a new object

    def step(self):
        """One cycle: the contact's edges, CFDP held or resumed, the dump for this cycle."""
        now = self.now()
        edge = self.contact.update(now)
        if edge is not None and self.enabled:  # off: a ground always in view, no events
            self._set("in_contact", edge == AOS)
            self._set("aos_count", self.contact.aos_count)
            self._set("passes", len(self.contact.windows))
            if self.il is not None:
                if edge == AOS:
                    self.il.emit("aos", {"passes": len(self.contact.windows)})
                else:
                    self.il.emit("los", {"backlog": self.backlog})
        if self.hold is not None:
            self.hold.update(self.contact.in_contact, self.clock())
        if not self.enabled:
            return
        self._sync()
        last, self._last = self._last, now
        if not self.contact.in_contact or last is None:
            self._credit = 0.0
        else:
            self._credit = min(self._credit + (now - last) * self.cycle_octets,
                               2 * self.cycle_octets + 2048)  # fmt: skip
        sent = {}  # store -> [first, last, count]
        while self._credit > 0:
            got = self.forward.next(now, budget=min(self._credit, self.forward.budget(now)))
            if got is None:
                break
            st, seq, raw = got
            self._credit -= len(raw)
            self.play(raw, st.vc)
            run = sent.get(st.id)
            if run is None:
                sent[st.id] = [seq, seq, 1]
            else:
                run[0], run[1], run[2] = min(run[0], seq), max(run[1], seq), run[2] + 1
        if sent:
            self._save()
        for sid, (first, last_seq, count) in sent.items():
            self.dumped += count
            self.event("passes.dumped", {"store": sid, "first": first, "last": last_seq,
                                         "count": count})  # fmt: skip
        backlog = self.forward.backlog()
        self.spare = 0.0 if backlog else self.cycle_octets
        self._set("backlog", backlog)
