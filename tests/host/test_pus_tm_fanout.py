"""The TM fan-out's targets: kept from one TM to the next for speed, they still follow every
change of the subscriber set (a new client, one that unsubscribes, one that falls silent)."""

from obsw_host.pus.tm_fanout import SUBSCRIBE, UNSUBSCRIBE, TmFanout

STATIC = ("127.0.0.1", 1)
A = ("127.0.0.1", 1000)
B = ("127.0.0.1", 1001)
TC = b"\x18" * 10


class Clock:
    def __init__(self):
        self.t = 0.0

    def __call__(self):
        return self.t


def test_targets_follow_every_change_of_the_set():
    clock = Clock()
    fan = TmFanout([STATIC], linger=60.0, clock=clock)
    assert fan.targets() == [STATIC]
    assert fan.heard(TC, A)
    assert fan.targets() == [STATIC, A]
    assert fan.targets() is fan.targets()  # unchanged set: the same list
    clock.t = 30.0
    assert not fan.heard(SUBSCRIBE, B)
    assert fan.targets() == [STATIC, A, B]
    clock.t = 61.0  # A silent for longer than the linger, B not
    assert fan.targets() == [STATIC, B]
    assert fan.heard(TC, A)  # A back
    assert fan.targets() == [STATIC, B, A]
    assert not fan.heard(UNSUBSCRIBE, B)
    assert fan.targets() == [STATIC, A]
    clock.t = 200.0  # every subscriber silent: the static address stays
    assert fan.targets() == [STATIC]
    assert fan.subscribers == {}


def test_a_refreshed_subscriber_is_kept_past_its_first_linger():
    clock = Clock()
    fan = TmFanout([], linger=60.0, clock=clock)
    fan.heard(TC, A)
    clock.t = 50.0
    fan.heard(TC, A)  # heard again: its linger starts afresh
    clock.t = 100.0
    assert fan.targets() == [A]
    clock.t = 111.0
    assert fan.targets() == []
