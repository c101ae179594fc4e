"""PLUTO activity calls and their arguments (ECSS-E-ST-70-32C Annex A): simple, record and
array arguments, activities and references handed as arguments, value sets, directives."""

from obsw.pluto.exprs import ExprParser
from obsw.pluto.lexer import WORD, PlutoSyntaxError
from obsw.pluto.syntax import RESERVED

_ARGUMENT_KINDS = ("activity", "parameter", "reporting data", "event", "system element")


class ArgumentParser(ExprParser):
    def activity_call(self):
        r = self.ref("an activity")
        args, dirs = (), ()
        if self.take("with", "arguments"):
            args = self.arguments()
            self.expect("end", "with", after="after the arguments")
        elif self.take("with", "value", "set"):
            args = (("value set", self.ref("a value set")),)
            self.expect("end", "with", after="after the value set")
        if self.take("with", "directives"):
            dirs = [self.named_expr()]
            while self.isop(","):
                self.i += 1
                dirs.append(self.named_expr())
            dirs = tuple(dirs)
            self.expect("end", "with", after="after the directives")
        return (r, args, dirs)

    def arguments_opt(self, opener):
        if not self.take(*opener):
            return ()
        a = self.arguments()
        self.expect("end", "with", after="after the arguments")
        return a

    def arguments(self, closer="with"):
        """Arguments up to 'end <closer>'."""
        out = [self.argument(closer)]
        while self.isop(","):
            self.i += 1
            out.append(self.argument(closer))
        return tuple(out)

    def argument(self, closer):
        """``[<name> :=] <expression>``, ``[<name>] record ... end record``, ``[<name>] array
        ... end array``, ``activity <call>``, ``parameter <ref>``, ``event <ref>``...: the
        forms overlap ('array X' is also a reference), so each that may start here is tried
        until one ends where an argument ends."""
        start = self.i
        err = None
        for form in (self._named, self._structured, self._typed, self._simple_argument):
            self.i = start
            try:
                a = form()
            except PlutoSyntaxError as e:
                if err is None or (e.line, e.col) > (err.line, err.col):
                    err = e
                continue
            if a is not None and (self.isop(",") or self.at("end", closer)):
                return a
        if err is None:
            self.i = start
            return self._simple_argument()
        raise err

    def _named(self):
        if self.tok()[0] != WORD or self.tok()[1] in RESERVED:
            return None
        name = self.name()
        if self.take(":="):  # 'name := record ...' too, an extension
            if self.at("record") or self.at("array"):
                return (name, self.structured(self.pos()))
            return (name, self.expr())
        if (self.at("record") or self.at("array")) and name not in _ARGUMENT_KINDS:
            return (name, self.structured(self.pos()))  # 'activity array X' is an activity
        return None

    def _structured(self):
        if self.at("record") or self.at("array"):
            return (None, self.structured(self.pos()))
        return None

    def _typed(self):
        p = self.pos()
        if self.take("activity"):  # an activity, with its arguments, handed to the one called
            return (None, ("act", p, self.activity_call()))
        if self.take("parameter") or self.take("reporting", "data"):
            r = self.ref()  # its value, as any reference to a parameter gives
            r[3] = r[3] or "parameter"
            return (None, r)
        if self.take("event"):  # the reference itself, not a value
            return (None, ("refarg", p, self.ref(), "event"))
        if self.take("system", "element"):
            return (None, ("refarg", p, self.ref(), "system element"))
        return None

    def _simple_argument(self):
        return (None, self.expr())

    def structured(self, p):
        if self.take("record"):
            v = ("rec", p, self.arguments("record"))
            self.expect("end", "record")
        else:
            self.expect("array")
            v = ("arr", p, self.arguments("array"))
            self.expect("end", "array")
        return v
