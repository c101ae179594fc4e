"""The FOP-1 state table (CCSDS 232.1-B-2 table 5-1) as data.

TABLE[event] holds one entry per state S1..S6: (next state or 0 to stay, action names). Action
``x`` is the method ``Fop1._a_x``. Events that cannot occur in a state (for example an
acknowledgement while initializing, when no AD frame is outstanding) follow the standard's
Alert reasons: SYNCH in S4, ignored in S5.
"""

_I = ()  # ignore
_SYNCH = (6, ("alert_synch",))
_CLCW = (6, ("alert_clcw",))
_NNR = (6, ("alert_nnr",))
_LOCKOUT = (6, ("alert_lockout",))
_LIMIT = (6, ("alert_limit",))
_T1 = (6, ("alert_t1",))
_LLIF = (6, ("alert_llif",))
_STAY = (0, _I)
_REJECT = (0, ("reject",))
_ACK_ALL = (1, ("remove_acked", "cancel_timer", "look_for_fdu"))
_ACK_SOME = (1, ("remove_acked", "look_for_fdu"))
_RETX = ("retransmit_ad", "look_for_fdu")


def _all(entry):
    return (entry,) * 6


def _s6_only(entry):
    return (_REJECT,) * 5 + (entry,)


def _setter(name):
    return _all((0, ("accept", name, "confirm")))


# Acknowledgement events cannot happen in S4/S5 (nothing outstanding): alert in S4, ignore in S5.
def _ack(s1, s2, s3):
    return (s1, s2, s3, _SYNCH, _STAY, _STAY)


TABLE = {
    # CLCW arrival (lockout 0, N(R) = V(S))
    1: (
        _STAY,
        _SYNCH,
        _SYNCH,
        (1, ("confirm", "cancel_timer")),
        (1, ("release_bc", "cancel_timer", "confirm")),
        _STAY,
    ),
    2: _ack(_ACK_ALL, _ACK_ALL, _ACK_ALL),
    3: (_CLCW, _CLCW, _CLCW, _CLCW, _CLCW, _STAY),
    4: (_SYNCH, _SYNCH, _SYNCH, _SYNCH, _STAY, _STAY),
    # CLCW arrival (lockout 0, NN(R) <= N(R) < V(S))
    5: _ack(_STAY, _SYNCH, _SYNCH),
    6: _ack(_ACK_SOME, _ACK_SOME, _ACK_SOME),
    7: _ack(_CLCW, _CLCW, _CLCW),
    101: _ack(*((6, ("remove_acked", "alert_limit")),) * 3),
    102: _ack(_LIMIT, _LIMIT, _LIMIT),
    8: _ack(*((2, ("remove_acked",) + _RETX),) * 3),
    9: _ack((3, ("remove_acked",)), (3, ("remove_acked",)), (3, ("remove_acked",))),
    10: _ack((2, _RETX), (2, _I), (2, _RETX)),
    11: _ack((3, _I), (3, _I), (3, _I)),
    12: _ack((2, _I), (2, _I), (2, _I)),
    103: _ack((3, _I), (3, _I), (3, _I)),
    13: (_NNR, _NNR, _NNR, _NNR, _STAY, _STAY),
    14: (_LOCKOUT, _LOCKOUT, _LOCKOUT, _LOCKOUT, _STAY, _STAY),
    15: (_CLCW, _CLCW, _CLCW, _CLCW, _CLCW, _STAY),
    # Timer expired: Transmission_Count < Limit (16: TT 0, 104: TT 1), else 17 (TT 0), 18 (TT 1)
    16: ((0, _RETX), (0, _RETX), _STAY, _T1, (0, ("retransmit_bc", "look_for_directive")), _STAY),
    104: (
        (0, _RETX),
        (0, _RETX),
        _STAY,
        (6, ("suspend",)),
        (0, ("retransmit_bc", "look_for_directive")),
        _STAY,
    ),
    17: (_T1, _T1, _T1, _T1, _T1, _STAY),
    18: ((6, ("suspend",)),) * 4 + (_T1, _STAY),
    # Requests to transfer FDUs
    19: (
        (0, ("add_to_wait", "look_for_fdu")),
        (0, ("add_to_wait", "look_for_fdu")),
        (0, ("add_to_wait",)),
        _REJECT,
        _REJECT,
        _REJECT,
    ),
    20: _all(_REJECT),
    21: _all((0, ("accept_bd",))),
    22: _all(_REJECT),
    # Directives
    23: _s6_only((1, ("accept", "initialize", "confirm"))),
    24: _s6_only((4, ("accept", "pend", "initialize", "start_timer"))),
    25: _s6_only((5, ("accept", "pend", "initialize", "transmit_unlock"))),
    26: _all(_REJECT),
    27: _s6_only((5, ("accept", "pend", "initialize", "set_vs", "transmit_set_vr"))),
    28: _all(_REJECT),
    29: ((6, ("accept", "alert_term", "confirm")),) * 5 + ((0, ("accept", "confirm")),),
    30: _all(_REJECT),
    31: _s6_only((1, ("accept", "resume", "confirm"))),
    32: _s6_only((2, ("accept", "resume", "confirm"))),
    33: _s6_only((3, ("accept", "resume", "confirm"))),
    34: _s6_only((4, ("accept", "resume", "confirm"))),
    35: _s6_only((0, ("accept", "set_vs", "confirm"))),
    36: _setter("set_window"),
    37: _setter("set_t1"),
    38: _setter("set_limit"),
    39: _setter("set_timeout_type"),
    40: _all(_REJECT),
    # Responses from the lower procedures
    41: ((0, ("ad_ready", "look_for_fdu")), (0, ("ad_ready", "look_for_fdu")))
    + ((0, ("ad_ready",)),) * 4,
    42: _all(_LLIF),
    43: ((0, ("bc_ready",)),) * 4 + ((0, ("bc_ready", "look_for_directive")), (0, ("bc_ready",))),
    44: _all(_LLIF),
    45: _all((0, ("bd_ready",))),
    46: _all(_LLIF),
}
