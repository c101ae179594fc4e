"""Several spacecraft on one Yamcs server: the checks made before anything starts.

Each mission of a fleet is its own mission folder (name, spacecraft id, port base) and its own
Yamcs instance (``instance.write_fleet``). ``problems(missions, http_port)`` lists, one line
each, what keeps them from running side by side: two missions with one instance name, one
spacecraft id, or one port on one host (their OBCs' ports on the host their mission files
name, Yamcs' link ports and the gateways' on the ground; the server's web port). ``check``
raises the first as a ``UserError``, which ``obsw`` prints as one line.
"""

from obsw_host.errors import UserError
from obsw_host.mission import ports as ports_module
from obsw_host.net import DEFAULT_HOST
from obsw_host.yamcs.instance import instance_name

GROUND = "127.0.0.1"  # Yamcs' links and the gateways listen on loopback of the Yamcs machine
# ports of a mission's OBC (its mission file's host); the rest are Yamcs' side
ONBOARD = ("pus", "cfdp", "tm", "playback")


def _host(ids):
    return ids.config.host if ids.config is not None else DEFAULT_HOST


def _used(ids):
    """(host, port) -> port name of every port mission ``ids`` uses, but Yamcs' web port (one
    for the server)."""
    out = {}
    for name, port in ids.ports.table().items():
        if name == "yamcs_http":
            continue
        host = _host(ids) if name in ONBOARD else GROUND
        out[(host, port)] = name
    return out


def problems(missions, http_port=None):
    """What keeps ``missions`` (``MissionIds``) from sharing one Yamcs, one line each."""
    found = []
    hint = ""
    base = ports_module.env_base()
    if base is not None:
        hint = "; $%s=%d moves every mission to that one base: unset it" % (ports_module.ENV, base)
    names, scids, owners = {}, {}, {}
    if http_port is not None:
        owners[(GROUND, http_port)] = ("the Yamcs server", "yamcs_http")
    for ids in missions:
        name = ids.name
        instance = instance_name(name)
        if instance in names:
            found.append(
                "missions %s and %s are both Yamcs instance %r; give each mission its own name "
                '(mission.json "name")' % (names[instance], name, instance)
            )
            continue
        names[instance] = name
        scid = ids.scid
        if scid is not None:
            if scid in scids:
                found.append(
                    "missions %s and %s both have spacecraft id %d; give each its own "
                    "(frames.scid in its spacecraft database)" % (scids[scid], name, scid)
                )
            scids.setdefault(scid, name)
        for where, port_name in _used(ids).items():
            other = owners.get(where)
            if other is not None:
                found.append(
                    "missions %s and %s both use port %d on %s (%s: %s, %s: %s); give each "
                    'mission its own port base (mission.json "ports": {"base": N})%s'
                    % (
                        other[0],
                        name,
                        where[1],
                        where[0],
                        other[0],
                        other[1],
                        name,
                        port_name,
                        hint,
                    )  # fmt: skip
                )
                break
            owners[where] = (name, port_name)
    return found


def check(missions, http_port=None):
    """Raise the first of ``problems`` as a one-line ``UserError``."""
    found = problems(missions, http_port)
    if found:
        raise UserError(found[0])
