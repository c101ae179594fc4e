"""cfdp-py's user, fault handler and check timers as the CFDP benchmarks drive them (cfdp.py in
memory, cfdp_udp.py across processes): the user notes the end of its transaction, the rest is
quiet."""


def peer_classes(check_timer_seconds):
    """(User, Faults, Timers): ``User(filestore)`` has ``done`` and ``condition`` once its
    transaction finished; ``Timers()`` gives check timers of ``check_timer_seconds``."""
    from cfdppy import CfdpUserBase
    from cfdppy.mib import CheckTimerProvider, DefaultFaultHandlerBase
    from spacepackets.countdown import Countdown

    class User(CfdpUserBase):
        done = False
        condition = None

        def transaction_finished_indication(self, params):
            self.done = True
            self.condition = params.finished_params.condition_code

        def _ignore(self, *a, **kw):
            pass

        transaction_indication = eof_sent_indication = metadata_recv_indication = _ignore
        file_segment_recv_indication = report_indication = suspended_indication = _ignore
        resumed_indication = fault_indication = abandoned_indication = _ignore
        eof_recv_indication = _ignore

    class Faults(DefaultFaultHandlerBase):
        def _ignore(self, *a, **kw):
            pass

        notice_of_suspension_cb = notice_of_cancellation_cb = abandoned_cb = ignore_cb = _ignore

    class Timers(CheckTimerProvider):
        def provide_check_timer(self, *a, **kw):
            return Countdown.from_seconds(check_timer_seconds)

    return User, Faults, Timers
