"""How a node waits for replies: attempts, retries, deadlines, local and remote routes.

``Calls`` is the half of ``Node`` that runs a request to its reply; ``obsw.il.node`` has the
public methods. A local provider is run by the waiting caller until the reply is there; a
remote one is waited for through ``Node.wait``, which a transport makes wake on I/O.
"""

from obsw.il.errors import (
    BUSY,
    OK,
    TIMEOUT,
    UNAVAILABLE,
    BusyError,
    CallTimeoutError,
    UnavailableError,
    cycle_error,
    error_from_reply,
)
from obsw.il.message import CALL
from obsw.il.proxy import Pending, unavailable

_RETRYABLE = (UNAVAILABLE, TIMEOUT, BUSY)


class Calls:
    """Request machinery shared by every ``Node``."""

    def _next_corr(self):
        self._corr = (self._corr + 1) & 0x7FFFFFFF or 1
        return self._corr

    def _deadline(self, timeout):
        if timeout is None:
            return None
        if timeout < 0:
            raise ValueError("timeout must be >= 0 seconds or None, got %r" % (timeout,))
        return self.clock.now() + timeout

    def _left(self, deadline):
        return 1.0 if deadline is None else deadline - self.clock.now()

    def _resolve(self, comp, deadline):
        """The route to ``comp``, waiting until ``deadline`` for one to appear."""
        while True:
            route = self.registry.resolve(comp)
            if route is not None:
                return route
            left = self._left(deadline)
            if left <= 0:
                raise unavailable(comp, "not registered")
            self.wait(self.resolve_interval if left > self.resolve_interval else left)

    def _request(self, kind, comp, member, payload, timeout, retries, user):
        attempt = 0
        while True:
            try:
                p = self._attempt(kind, comp, member, payload, self._deadline(timeout), user)
            except (UnavailableError, CallTimeoutError, BusyError):
                if attempt >= retries:
                    raise
                attempt += 1
                self.retries += 1
                continue
            if p.accepted:
                return p
            if p.status == OK:
                return p.value
            if p.status in _RETRYABLE and attempt < retries:
                attempt += 1
                self.retries += 1
                continue
            raise error_from_reply(p.status, p.value, p.target)

    def _chain(self, user):
        busy = self._busy
        if user is not None and user not in busy:
            busy.append(user)
            return True
        return False

    def _attempt(self, kind, comp, member, payload, deadline, user):
        busy = self._busy
        pushed = self._chain(user)
        try:
            if comp in busy:
                raise cycle_error(busy[busy.index(comp) :] + [comp], comp + "." + str(member))
            chain = tuple(busy)
            while True:
                route = self._resolve(comp, deadline)
                p = Pending(self, comp, member)
                if route.local:
                    route.accept((kind, 0, comp, member, payload, chain, p))
                    self._wait_reply(p, route, deadline)
                    return p
                if self._remote(p, route, kind, payload, chain, deadline):
                    return p
                self.registry.forget_route(route)  # link went down: resolve again
                left = self._left(deadline)
                if left <= 0:
                    raise unavailable(comp, "link went down")
                self.wait(self.resolve_interval if left > self.resolve_interval else left)
        finally:
            if pushed:
                busy.remove(user)

    def _remote(self, p, route, kind, payload, chain, deadline):
        corr = self._next_corr()
        p.corr = corr
        p.route = route
        self._pending[corr] = p
        waiter = chain[-1] if chain else None
        if waiter is not None:
            self._waits[waiter] = p.component
        try:
            if not route.send((kind, corr, p.component, p.member, payload, chain, None)):
                return False
            self._wait_reply(p, route, deadline)
            return not p.lost
        finally:
            if waiter is not None:
                self._waits.pop(waiter, None)
            if not p.accepted:
                self._pending.pop(corr, None)

    def _wait_reply(self, p, route, deadline):
        local = route.local
        while not p.replied and not p.lost:
            if local and route.step():
                if p.replied:
                    return
            left = self._left(deadline)
            if left <= 0:
                raise CallTimeoutError(
                    "no reply from %s within the timeout" % p.target, p.target, deadline
                )
            if not local or not route.inbox._count:
                self.wait(left)

    def _wait_done(self, p, timeout):
        deadline = self._deadline(timeout)
        route = p.route
        while not p.done:
            if route is not None and route.local and route.step():
                continue
            left = self._left(deadline)
            if left <= 0:
                raise CallTimeoutError(
                    "no outcome of %s within %ss" % (p.target, timeout), p.target
                )
            self.wait(left)

    def _start(self, comp, member, payload, timeout, user, on_status):
        pushed = self._chain(user)
        try:
            route = self._resolve(comp, self._deadline(timeout))
            chain = tuple(self._busy)
        finally:
            if pushed:
                self._busy.remove(user)
        p = Pending(self, comp, member, on_status)
        p.route = route
        if route.local:
            route.accept((CALL, 0, comp, member, payload, chain, p))
            ev = self._activity
            if ev is not None:
                ev.set()
        else:
            p.corr = self._next_corr()
            self._pending[p.corr] = p
            if not route.send((CALL, p.corr, comp, member, payload, chain, None)):
                self.registry.forget_route(route)
                p._lose()
        return p

    async def _arequest(self, kind, comp, member, payload, timeout, retries=0, user=None):
        """``_request`` for asyncio tasks: remote replies are awaited, not polled for."""
        import asyncio  # only here: boards without asyncio still import this module

        attempt = 0
        while True:
            deadline = self._deadline(timeout)
            route = self.registry.resolve(comp)
            if route is None or route.local:
                return self._request(kind, comp, member, payload, timeout, retries, user)
            p = Pending(self, comp, member)
            p.corr = self._next_corr()
            p.route = route
            p._event = asyncio.Event()
            self._pending[p.corr] = p
            chain = (user,) if user is not None else ()
            if user is not None:
                self._waits[user] = comp
            try:
                if route.send((kind, p.corr, comp, member, payload, chain, None)):
                    while not p.replied and not p.lost:
                        p._event.clear()
                        left = self._left(deadline)
                        if left <= 0:
                            break
                        try:
                            await asyncio.wait_for(p._event.wait(), left)
                        except asyncio.TimeoutError:
                            break
                else:
                    p.lost = True
            finally:
                if user is not None:
                    self._waits.pop(user, None)
                if not p.accepted:
                    self._pending.pop(p.corr, None)
            if p.replied and not p.lost:
                if p.accepted:
                    return p
                if p.status == OK:
                    return p.value
                if p.status not in _RETRYABLE or attempt >= retries:
                    raise error_from_reply(p.status, p.value, p.target)
            elif attempt >= retries:
                if p.lost:
                    raise unavailable(comp, "link went down")
                raise CallTimeoutError(
                    "no reply from %s within %ss" % (p.target, timeout), p.target
                )
            if p.lost:
                self.registry.forget_route(route)
            attempt += 1
            self.retries += 1
