"""What SpaceCAN state machines report to the application: one small event type with a kind."""

# Event kinds, named once.
BUS_SWITCHED = "bus_switched"  # old, new, reason
TX_ERROR = "tx_error"  # bus, count
SYNC = "sync"  # bus
SCET = "scet"  # bus, value (ScetTime)
UTC = "utc"  # bus, value (UtcTime)
VERIFICATION = "verification"  # node, subtype, service, req_subtype, request (or None)
REQUEST_DONE = "request_done"  # request
PING_REPORT = "ping_report"  # node
PARAMETER_REPORT = "parameter_report"  # node, values {id: value}
HOUSEKEEPING_REPORT = "housekeeping_report"  # node, report_id, values {id: value}
PACKET = "packet"  # node, packet (a report no service here understands)
DECODE_ERROR = "decode_error"  # node, packet, error
FUNCTION_CALL = "function_call"  # function_id, args, ok (responder)
PARAMETERS_SET = "parameters_set"  # values (responder)
HK_CHANGED = "hk_changed"  # report_ids, enabled (responder)
REQUEST_REJECTED = "request_rejected"  # service, subtype, reason (responder)
FRAME_ERROR = "frame_error"  # bus, can_id, error


class Event:
    """kind, time and the fields of that kind as attributes (see the kinds above)."""

    def __init__(self, kind, time, **fields):
        self.kind = kind
        self.time = time
        self.fields = fields
        for k in fields:
            setattr(self, k, fields[k])

    def __repr__(self):
        items = ", ".join("%s=%r" % (k, self.fields[k]) for k in sorted(self.fields))
        return "Event(%s, t=%.3f%s)" % (self.kind, self.time, ", " + items if items else "")
