"""Secure by default: the OBC's frame processor runs with SDLS unless the mission says "none".

A mission whose processes run ``frames`` must either name its key file (``frames.keys``),
which has to exist, be readable by its owner only and hold at least one operational TC SA,
or say ``"tc_security": "none"`` in its ``frames`` section; then every start logs that TC
frames are accepted without authentication. Anything else refuses to start with one line.
"""

from obsw.frames.sdls import SA_OPERATIONAL
from obsw.frames.sdls_keys import KeyFileError, load_sas

from obsw_host.mission import defaults

OFF_WARNING = (
    'frames: TC SECURITY OFF (frames.tc_security is "none"): every well-formed TC frame is '
    "accepted, from anyone"
)


def check(config):
    """The key file path the frame processor must use, or None when the mission switched TC
    security off; ConfigError (one line) when neither holds."""
    from obsw_host.frames.keys import read_key_file
    from obsw_host.mission.config import ConfigError

    opts = config.section("frames")
    mode = opts.get("tc_security", defaults.FRAMES["tc_security"])
    if mode not in ("sdls", "none"):
        raise ConfigError("frames.tc_security", 'expected "sdls" or "none", got %r' % (mode,))
    path = opts.get("keys")
    if mode == "none":
        if path:
            raise ConfigError("frames.tc_security", '"none" with a key file: say one or the other')
        return None
    if not path:
        raise ConfigError(
            "frames.keys",
            "TC security is on by default: name the mission's key file, or set "
            'frames.tc_security to "none" to command without authentication',
        )
    path = config.resolve(path)
    try:
        sas = load_sas(read_key_file(path))
    except (KeyFileError, OSError) as e:
        raise ConfigError("frames.keys", "no usable key material: %s" % e) from None
    if not [sa for sa in sas if sa.link == "tc" and sa.state == SA_OPERATIONAL]:
        raise ConfigError("frames.keys", "%s has no operational TC SA" % path)
    return path
