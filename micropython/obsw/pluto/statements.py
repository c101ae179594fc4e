"""PLUTO statement execution as generators: each yields None before a statement and a Wait
while it waits, so the interpreter can stop between any two statements."""

from obsw.pluto.evaluate import Evaluator, _Ask, _cmp, convert_answer
from obsw.pluto.units import AbsTime, arith, seconds, text

_PENDING = object()
CONFIRMED = "confirmed"
NOT_CONFIRMED = "not confirmed"
ABORTED = "aborted"


class Wait:
    """What a procedure waits for: a deadline (or None), activity handles, a user question."""

    def __init__(self, deadline=None, activity=None, prompt=None):
        self.deadline = deadline
        self.activities = [] if activity is None else [activity]
        self.prompt = prompt

    def merge(self, o):
        if o.deadline is not None and (self.deadline is None or o.deadline < self.deadline):
            self.deadline = o.deadline
        self.activities.extend(o.activities)
        self.prompt = self.prompt or o.prompt

    def __repr__(self):
        return "Wait(%r, %r, %r)" % (self.deadline, self.activities, self.prompt)


class _Abort(Exception):
    def __init__(self, msg):
        super().__init__(msg)


class _Terminate(Exception):
    pass


class _Timeout(Exception):
    def __init__(self, entry):
        super().__init__("timeout")
        self.entry = entry


class Statements(Evaluator):
    def raise_event(self, name):
        self.evcounts[name] = self.evcounts.get(name, 0) + 1
        self.system.raise_event(name, None)

    def _evcount(self, key):
        if key in self.evcounts:
            return self.evcounts[key]
        return self.system.event_count(key)

    def _block(self, stmts):
        for s in stmts:
            self.cur = s
            yield None
            if self.ts[0]:
                self._expired()
            k = s[0]
            if k == "set":
                while True:
                    try:
                        self.assign(s[2], self.eval(s[3]))
                        break
                    except _Ask as a:
                        yield from self._answer_for(a.node)
            elif k == "log" or k == "inform":
                vs = []
                for e in s[2]:
                    v = self._val(e)
                    if v is _PENDING:
                        v = yield from self._ev(e)
                    vs.append(text(v))
                (self.system.log if k == "log" else self.system.inform_user)("".join(vs))
            else:
                yield from self._statement(s)

    def _statement(self, s):
        k = s[0]
        if k == "if":
            c = self._val(s[2])
            if c is _PENDING:
                c = yield from self._ev(s[2])
            yield from self._block(s[3] if c else s[4])
        elif k == "case":
            v = self._val(s[2])
            if v is _PENDING:
                v = yield from self._ev(s[2])
            self.subjects.append(v)
            try:
                body = s[4] or ()
                for tag, b in s[3]:
                    if self.eval(tag):
                        body = b
                        break
            finally:
                self.subjects.pop()
            yield from self._block(body)
        elif k == "while" or k == "repeat" or k == "for":
            yield from self._loop(s)
        elif k == "wait":
            yield from self._wait(s)
        elif k == "conf" or k == "op":
            yield from self._confirm(
                lambda: self._activity(s, True), s[4] if k == "conf" else None, s
            )
        elif k == "init":
            yield from self._activity(s, False)
        elif k == "step":
            yield from self._confirm(lambda: self._step_body(s), s[4], s)
        elif k == "par":
            yield from self._parallel(s)
        elif k == "ctx":
            yield from self._block(s[3])
        elif k == "save":
            self._save(s[2])

    def _push(self, to, owner):
        e = [self.now + seconds(self.eval(to[0])), to[1], self.ts[1], owner]
        lst = self.ts[0]
        lst.append(e)
        return lst, e

    def _expired(self):
        for e in self.ts[0]:
            if self.now >= e[0]:
                if e[1]:
                    self.raise_event(e[1])
                raise _Timeout(e)

    def _deadline(self, d):
        for e in self.ts[0]:
            if d is None or e[0] < d:
                d = e[0]
        return d

    def _loop(self, s):
        k = s[0]
        to = s[3] if k == "while" else s[4] if k == "repeat" else s[6]
        lst = e = None
        if to:
            lst, e = self._push(to, s)
        try:
            if k == "while":
                while True:
                    c = self._val(s[2])
                    if c is _PENDING:
                        c = yield from self._ev(s[2])
                    if not c:
                        break
                    yield from self._block(s[4])
            elif k == "repeat":
                while True:
                    yield from self._block(s[2])
                    c = self._val(s[3])
                    if c is _PENDING:
                        c = yield from self._ev(s[3])
                    if c:
                        break
            else:
                r, step = s[2], 1 if s[5] is None else self.eval(s[5])
                stop = self.eval(s[4])
                self.assign(r, self.eval(s[3]))
                down = (step.value if hasattr(step, "value") else step) < 0
                while True:
                    if _cmp("<" if down else ">", self.read(r), stop):
                        break
                    yield from self._block(s[7])
                    v = self.read(r)
                    tv = type(v)
                    self.assign(r, v + step if tv is int or tv is float else arith("+", v, step))
                    if self.ts[0]:
                        self._expired()
        finally:
            if e:
                lst.remove(e)

    def _wait(self, s, own=False):
        yield from self._wait_until(s)
        if len(s) > 5 and s[5]:  # save context: the values as they are when the wait ends
            self._save(s[5])

    def _save(self, items):
        vals = []
        for item in items:  # every value read first: one consistent snapshot
            vals.append(self.eval(item[0]))
        for i, item in enumerate(items):
            self.vars[item[2]] = vals[i]

    def _wait_until(self, s):
        mode, x, to = s[2], s[3], s[4]
        lst = e = None
        if to:
            lst, e = self._push(to, s)
        try:
            if mode == "event":
                key = x[5]
                base = self._evcount(key)
                while self._evcount(key) <= base:
                    self._expired()
                    yield Wait(self._deadline(self.now + self.poll))
                return
            v = self.eval(x)
            if mode == "for" or isinstance(v, AbsTime):
                target = v.seconds if isinstance(v, AbsTime) else self.now + seconds(v)
                while self.now < target:
                    self._expired()
                    yield Wait(self._deadline(target))
                return
            while not self.eval(x):
                self._expired()
                yield Wait(self._deadline(self.now + self.poll))
        finally:
            if e:
                lst.remove(e)

    def _activity(self, s, confirm):
        call = (s[2], s[3], ()) if s[0] == "op" else s[2]
        args = {}
        for i, (name, v) in enumerate(call[1]):
            args[name or "arg%d" % (i + 1)] = yield from self._argument(v)
        for i, (name, v) in enumerate(call[2]):
            args.setdefault("directives", {})[name or "arg%d" % (i + 1)] = self.eval(v)
        h = self.system.initiate(call[0][5], args, confirm)
        if s[0] != "op" and s[3]:
            self.refer[s[3]] = h
        if not confirm:
            return None
        return (yield from self._await(h))

    def _argument(self, v):
        if v[0] == "rec":
            d = {}
            for i, (n, x) in enumerate(v[2]):
                d[n or "arg%d" % (i + 1)] = yield from self._argument(x)
            return d
        if v[0] == "arr":
            out = []
            for _, x in v[2]:
                out.append((yield from self._argument(x)))
            return out
        if v[0] == "r" and v[4] == "act":
            return v[5]
        if v[0] == "refarg":
            return v[2][5]
        if v[0] == "act":  # an activity handed on: its name, with its arguments if any
            call, args = v[2], {}
            for i, (name, x) in enumerate(call[1]):
                args[name or "arg%d" % (i + 1)] = yield from self._argument(x)
            if not args:
                return call[0][5]
            return {"activity": call[0][5], "arguments": args}
        x = self._val(v)
        if x is _PENDING:
            x = yield from self._ev(v)
        return x

    def _await(self, h):
        try:
            while True:
                st = self.system.status(h)
                if st:
                    return st
                self._expired()
                yield Wait(self._deadline(self.now + self.poll), h)
        except GeneratorExit:
            self.system.abort_activity(h)
            raise

    def _parallel(self, s):
        every = s[2]
        parent = self.ts
        states = [[list(parent[0]), parent[1]] for _ in s[3]]
        gens = [self._statement(b) for b in s[3]]
        live = list(range(len(gens)))
        try:
            while live:
                merged = None
                for i in tuple(live):
                    g = gens[i]
                    while True:
                        self.ts = states[i]
                        try:
                            w = next(g)
                        except StopIteration:
                            live.remove(i)
                            w = False
                        finally:
                            self.ts = parent
                        if w is None:
                            yield None
                            continue
                        break
                    if w is False:
                        if not every:
                            return
                    elif merged is None:
                        merged = w
                    else:
                        merged.merge(w)
                if live:
                    yield merged
        finally:
            for i in live:
                gens[i].close()
                b = s[3][i]
                if b[0] == "step":
                    self.step_status[b[2]] = ABORTED

    def _ask(self, question):
        self.question = question
        ans = self.system.ask_user(question)
        if ans is None:
            self._answer = None
            while self._answer is None:
                yield Wait(None, None, question)
            ans = self._answer
            self._answer = None
        self.question = None
        return ans

    def _answer_for(self, node):
        q = text(self.eval(node[2]))
        ans = yield from self._ask(q)
        if (ans is None or ans == "") and node[3] is not None:
            ans = self.eval(node[3])
        self.answers[id(node)] = convert_answer(ans, node[4])

    def _val(self, e):
        try:
            return self.eval(e)
        except _Ask as a:
            self._asking = a.node
            return _PENDING

    def _ev(self, e):
        yield from self._answer_for(self._asking)
        while True:
            try:
                return self.eval(e)
            except _Ask as a:
                yield from self._answer_for(a.node)
