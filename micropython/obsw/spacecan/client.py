"""The SpaceCAN controller's service layer: requests per PUS-like service and their reports."""

from obsw.spacecan import events as ev
from obsw.spacecan import packets as pk
from obsw.spacecan.requests import ACCEPTED, COMPLETED, FAILED, REJECTED, RequestError


class ServiceClient:
    """Mixed into Controller: builds service requests and matches reports to them."""

    # -- reports -------------------------------------------------------------------------------

    def _dispatch(self, node, service, subtype, data, bus, now):
        if service == pk.SERVICE_VERIFICATION:
            if len(data) < 2:
                self._emit(
                    ev.DECODE_ERROR,
                    now,
                    node=node,
                    packet=bytes((service, subtype)) + data,
                    error="verification report needs 2 data bytes, got %d" % len(data),
                )
                return
            req = self._head(node, data[0], data[1])
            self._emit(
                ev.VERIFICATION,
                now,
                node=node,
                subtype=subtype,
                service=data[0],
                req_subtype=data[1],
                request=req,
                bus=bus,
            )
            if req is None:
                self.counters["unmatched"] += 1
                return
            req.reports.append(subtype)
            if subtype == pk.ACCEPT_OK:
                req.status = ACCEPTED
                req.deadline = now + req.completion_timeout
            elif subtype == pk.ACCEPT_FAIL:
                self._finish(
                    req,
                    REJECTED,
                    now,
                    "node %d rejected (%d,%d)" % (node, req.service, req.subtype),
                )
            elif subtype == pk.COMPLETE_OK:
                if req.result is None and req.key[1:] == (pk.SERVICE_TEST, pk.PING):
                    req.result = True
                self._finish(req, COMPLETED, now)
            elif subtype == pk.COMPLETE_FAIL:
                self._finish(
                    req, FAILED, now, "node %d failed (%d,%d)" % (node, req.service, req.subtype)
                )
            return
        nodedef = self.nodes.get(node)
        try:
            if service == pk.SERVICE_TEST and subtype == pk.PING_REPORT:
                req = self._head(node, pk.SERVICE_TEST, pk.PING)
                if req is not None:
                    req.result = True
                self._emit(ev.PING_REPORT, now, node=node, bus=bus)
            elif service == pk.SERVICE_PARAMETER and subtype == pk.PARAM_REPORT:
                if nodedef is None:
                    raise pk.ServicePacketError("no node definition for node %d" % node)
                values = dict(pk.unpack_values(nodedef, data))
                req = self._head(node, pk.SERVICE_PARAMETER, pk.PARAM_REQUEST)
                if req is not None:
                    req.result = values
                self._emit(ev.PARAMETER_REPORT, now, node=node, values=values, bus=bus)
            elif service == pk.SERVICE_HOUSEKEEPING and subtype == pk.HK_REPORT:
                if nodedef is None:
                    raise pk.ServicePacketError("no node definition for node %d" % node)
                rid, pairs = pk.unpack_hk(nodedef, data)
                values = dict(pairs)
                req = self._head(node, pk.SERVICE_HOUSEKEEPING, pk.HK_ONE_SHOT)
                if req is not None:
                    if req.result is None:
                        req.result = {}
                    req.result[rid] = values
                self._emit(
                    ev.HOUSEKEEPING_REPORT, now, node=node, report_id=rid, values=values, bus=bus
                )
            else:
                self._emit(
                    ev.PACKET,
                    now,
                    node=node,
                    packet=pk.ServicePacket(service, subtype, data),
                    bus=bus,
                )
        except ValueError as e:
            self._emit(
                ev.DECODE_ERROR,
                now,
                node=node,
                packet=bytes((service, subtype)) + data,
                error=str(e),
            )

    # -- service helpers -----------------------------------------------------------------------

    def _nodedef(self, node_id):
        if node_id not in self.nodes or self.nodes[node_id] is None:
            raise RequestError("node %d has no node definition" % node_id, node_id)
        return self.nodes[node_id]

    def ping(self, node_id, now, **kw):
        """(17,1) connection test; result True."""
        return self.request(node_id, pk.SERVICE_TEST, pk.PING, b"", now, **kw)

    def request_parameters(self, node_id, parameter_ids, now, **kw):
        """(20,1); result {parameter_id: value} from the (20,2)."""
        return self.request(
            node_id, pk.SERVICE_PARAMETER, pk.PARAM_REQUEST, pk.pack_ids(parameter_ids), now, **kw
        )

    def set_parameters(self, node_id, values, now, **kw):
        """(20,3), our extension: values {parameter_id: value}; spacecan nodes reject it."""
        data = pk.pack_values(self._nodedef(node_id), values)
        return self.request(node_id, pk.SERVICE_PARAMETER, pk.PARAM_SET, data, now, **kw)

    def call_function(self, node_id, function_id, now, args=None, **kw):
        """(8,1) perform function with args {argument_id: value} (None or {} for none)."""
        if args is not None and not isinstance(args, dict):
            raise RequestError(
                "function arguments must be a dict {argument_id: value} or None, got %r" % (args,),
                node_id,
            )
        data = pk.pack_function(self.nodes.get(node_id), function_id, args)
        return self.request(node_id, pk.SERVICE_FUNCTION, pk.FUNCTION_PERFORM, data, now, **kw)

    def enable_housekeeping(self, node_id, report_ids, now, **kw):
        """(3,5) enable periodic reports."""
        return self.request(
            node_id, pk.SERVICE_HOUSEKEEPING, pk.HK_ENABLE, pk.pack_ids(report_ids), now, **kw
        )

    def disable_housekeeping(self, node_id, report_ids, now, **kw):
        """(3,6) disable periodic reports."""
        return self.request(
            node_id, pk.SERVICE_HOUSEKEEPING, pk.HK_DISABLE, pk.pack_ids(report_ids), now, **kw
        )

    def request_housekeeping(self, node_id, report_ids, now, **kw):
        """(3,27) one-shot reports; result {report_id: {parameter_id: value}}."""
        return self.request(
            node_id, pk.SERVICE_HOUSEKEEPING, pk.HK_ONE_SHOT, pk.pack_ids(report_ids), now, **kw
        )
