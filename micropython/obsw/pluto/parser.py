"""PLUTO statement parser (ECSS-E-ST-70-32C Annex A) producing a small AST of tuples.

A procedure or step definition is ``("def", pos, decls, preconditions, main, watchdog,
confirmation)``; statements are tuples tagged by their first item (see README, PLUTO section).
"""

from obsw.pluto.arguments import ArgumentParser
from obsw.pluto.exprs import SUBJECT
from obsw.pluto.lexer import EOF, OP, STR, WORD, PlutoSyntaxError, line_col, tokenize
from obsw.pluto.syntax import MAX_NESTING, _show

# Deepest tree (tuples and lists) a procedure may give: long operator chains such as
# 1 + 1 + ... + 1 nest without any parenthesis.
MAX_TREE_DEPTH = 6 * MAX_NESTING

_STATUS = (("confirmed",), ("not", "confirmed"), ("aborted",))
# words that carry an expression on: after 'wait for event X' they make it 'wait for <expr>'
_GOES_ON = ("AND", "OR", "XOR", "between", "within", "in")
_MAIN_STOPS = ("end", "watchdog", "confirmation")
_PROC_ONLY = (
    "only initiate, initiate and confirm, in parallel, inform user, log and in the context of"
    " are allowed in a procedure main body; put %s in a step"
)


def parse(src):
    """Parse procedure text into its definition node; raises PlutoSyntaxError."""
    parser = Parser(tokenize(src, True))
    try:
        tree = parser.procedure()
    except RuntimeError:
        # the C stack ran out before MAX_NESTING did (a Pyboard's 16 KiB stack holds about
        # five levels of parentheses, fewer under a deep caller): a load error all the same
        raise PlutoSyntaxError("nesting too deep for the stack", *line_col(parser.pos())) from None
    check_depth(tree)
    return tree


def check_depth(tree):
    """PlutoSyntaxError at the first node nested deeper than MAX_TREE_DEPTH (no recursion)."""
    stack = [(tree, 1, 0)]
    while stack:
        node, depth, p = stack.pop()
        if len(node) > 1 and type(node[0]) is str and type(node[1]) is int:
            p = node[1]
        if depth > MAX_TREE_DEPTH:
            raise PlutoSyntaxError("nesting deeper than %d levels" % MAX_NESTING, *line_col(p))
        for child in node:
            t = type(child)
            if (t is tuple or t is list) and child:
                stack.append((child, depth + 1, p))


class Parser(ArgumentParser):
    def procedure(self):
        self.expect("procedure", after="at the start of the text")
        node = self.definition(False, "procedure")
        self.expect("end", "procedure")
        if self.tok()[0] != EOF:
            self.err("expected end of text after 'end procedure', found %s" % _show(self.tok()))
        return node

    def definition(self, step, what):
        p = self.pos()
        decls = self.declarations(step) if self.at("declare") else []
        pre = self.conditions("preconditions") if self.at("preconditions") else None
        if self.take("main"):
            main = self.stmts(step, ("end",))
            self.expect("end", "main")
        else:
            main = self.stmts(step, _MAIN_STOPS)
        if not main:
            self.err("the %s main body needs at least one statement" % what)
        wd = None
        if self.take("watchdog"):
            wd = []
            while True:
                if not self.at("initiate", "and", "confirm", "step"):
                    self.err("a watchdog body holds 'initiate and confirm step' statements")
                st = self.statement(True)
                if st[0] != "step":
                    self.err("a watchdog body holds steps, found an activity", st[1])
                wd.append(st)
                self.expect(";", after="after the watchdog step")
                self.take("watchdog")
                if self.take("end", "watchdog"):
                    break
        conf = self.conditions("confirmation") if self.at("confirmation") else None
        return ("def", p, decls, pre, main, wd, conf)

    def declarations(self, step):
        self.expect("declare")
        out = []
        while True:
            p = self.pos()
            if self.take("event"):
                out.append(("event", p, self.name("an event name"), self.described()))
            elif step and self.take("variable"):
                n = self.name("a variable name")
                self.expect("of", "type", after="after the variable name")
                t = self.typ()
                u = self.unit() if self.take("with", "units") else None
                out.append(("var", p, n, t, u, self.described()))
            elif step and self.take("enumerated"):
                n = self.name("a set name")
                self.expect("(")
                vals = [self.string()]
                while self.isop(","):
                    self.i += 1
                    vals.append(self.string())
                self.expect(")")
                out.append(("enum", p, n, tuple(vals), self.described()))
            else:
                self.err(
                    "expected %s declaration, found %s"
                    % (
                        "an event, variable or enumerated set" if step else "an event",
                        _show(self.tok()),
                    )  # fmt: skip
                )
            if not self.isop(","):
                break
            self.i += 1
        self.expect("end", "declare")
        return out

    def string(self):
        t = self.tok()
        if t[0] != STR:
            self.err("expected a string constant, found %s" % _show(t))
        self.i += 1
        return t[1]

    def described(self):
        return self.string() if self.take("described", "by") else None

    def conditions(self, body):
        self.expect(body)
        out = []
        while True:
            p = self.pos()
            if self.take("if"):
                out.append(("if", p, self.expr()))
            elif self.at("wait"):
                out.append(self.statement(True))
            else:
                self.err(
                    "expected 'if' or 'wait' in the %s body, found %s" % (body, _show(self.tok()))
                )
            if not self.take("then"):
                break
        self.expect("end", body)
        return out

    def stmts(self, step, stops):
        self.enter()
        out = []
        while True:
            t = self.tok()
            if t[0] == EOF or (t[0] == WORD and t[1] in stops):
                self.depth -= 1
                return out
            out.append(self.statement(step))
            self.expect(";", after="after the statement")

    def timeout(self):
        if not self.at("timeout"):
            return None
        p = self.pos()
        self.i += 1
        e = self.expr()
        ev = self.name("an event name") if self.take("raise", "event") else None
        return (e, ev, p)

    def statement(self, step):
        p = self.pos()
        if self.at("initiate", "and", "confirm", "step"):
            # always a step: Annex A also reads 'initiate and confirm step X;' as an activity
            # whose reference has object type step, which no activity has
            self.i += 3
            return self.step_statement(p)
        if self.take("initiate", "and", "confirm"):
            return self.confirm_activity(p)
        if self.take("initiate"):
            c = self.activity_call()
            return ("init", p, c, self.name() if self.take("refer", "by") else None)
        if self.take("in", "parallel"):
            return self.parallel(p)
        if self.take("in", "the", "context", "of"):
            r = self.ref()
            self.expect("do", after="after the context")
            body = self.stmts(step, ("end",))
            self.expect("end", "context")
            return ("ctx", p, r, body)
        if self.take("inform", "user"):
            return ("inform", p, self.expr_list())
        if self.take("log"):
            return ("log", p, self.expr_list())
        if not step:
            self.err(_PROC_ONLY % _show(self.tok()))
        if self.take("if"):
            c = self.expr()
            self.expect("then", after="after the if condition")
            a = self.stmts(True, ("else", "end"))
            b = self.stmts(True, ("end",)) if self.take("else") else []
            self.expect("end", "if")
            return ("if", p, c, a, b)
        if self.take("in", "case"):
            return self.case(p)
        if self.take("save", "context", "refer"):
            return self.save_context(p)
        if self.take("while"):
            c = self.expr()
            to = self.timeout()
            self.expect("do", after="after the while condition")
            body = self.stmts(True, ("end",))
            self.expect("end", "while")
            return ("while", p, c, to, body)
        if self.take("repeat"):
            body = self.stmts(True, ("until",))
            self.expect("until")
            c = self.expr()
            return ("repeat", p, body, c, self.timeout())
        if self.take("for"):
            r = self.ref("a loop variable")
            self.expect(":=", after="after the loop variable")
            a = self.expr()
            self.expect("to", after="after the start value")
            b = self.expr()
            by = self.expr() if self.take("by") else None
            to = self.timeout()
            self.expect("do", after="after the for range")
            body = self.stmts(True, ("end",))
            self.expect("end", "for")
            return ("for", p, r, a, b, by, to, body)
        if self.take("wait"):
            if self.take("until"):
                mode, x = "until", self.expr()
            elif self.take("for"):
                mode, x = "for", None
                start = self.i
                if self.take("event"):
                    mode, x = "event", self.ref("an event")
                    t = self.tok()
                    if t[0] == OP and t[1] != ";" or t[1] in _GOES_ON:
                        # 'wait for event X AND Y': the expression 'event X AND Y' is waited
                        self.i, mode = start, "for"
                if mode == "for":
                    x = self.expr()
            else:
                self.err("expected 'until' or 'for' after 'wait', found %s" % _show(self.tok()))
            saved = self.save_items() if self.take("save", "context", "refer") else None
            return ("wait", p, mode, x, self.timeout(), saved)
        if self.tok()[0] != WORD:
            self.err("expected a statement, found %s" % _show(self.tok()))
        r = self.ref("a statement")
        if self.take(":="):
            return ("set", p, r, self.expr())
        if self.tok()[0] == WORD and self.object_type_here():  # 'open variable x': 'of' left out
            r[2] = r[2] + tuple(self.ref("an object")[2])
        return ("op", p, r, self.arguments_opt(("with",)))

    def step_statement(self, p):
        self.expect("step")
        n, d = self.named_step()
        self.expect("end", "step")
        return ("step", p, n, d, self.continuation())

    def confirm_activity(self, p):
        c = self.activity_call()
        r = self.name() if self.take("refer", "by") else None
        return ("conf", p, c, r, self.continuation())

    def named_step(self):
        """A step's name and definition. Without 'main', 'step A B x := 1;' may be step 'A B'
        or step 'A' doing 'B x := 1': when the body cannot start right after the name, its
        last words are given to the body, one at a time."""
        start = self.i
        self.name("a step name")
        limit = self.i - start
        while True:
            self.i = start
            n = self.name("a step name", limit)
            body = self.i
            try:
                return n, self.definition(True, "step")
            except PlutoSyntaxError as e:
                if limit == 1 or line_col(self.toks[body][2]) != (e.line, e.col):
                    raise
                limit -= 1

    def save_context(self, p):
        """``save context refer to <reference> by <name> {, to <reference> by <name>}
        [end context]``."""
        items = self.save_items()
        self.take("end", "context")
        return ("save", p, items)

    def save_items(self):
        """The pairs of a save context (after 'save context refer'), as [reference, name,
        variable key (set by the checker)]; 'refer' may be repeated after ','."""
        items = []
        while True:
            self.expect("to", after="after 'save context refer'")
            r = self.ref("a reporting data reference")
            self.expect("by", after="after the saved reference")
            items.append([r, self.name("a name for the saved value"), None])
            if not (self.isop(",") and self.tok(1)[1] in ("to", "refer")):
                return items
            self.i += 1
            self.take("refer")

    def expr_list(self):
        out = [self.expr()]
        while self.isop(","):
            self.i += 1
            out.append(self.expr())
        return tuple(out)

    def case(self, p):
        subject = self.expr()
        branches = []
        other = None
        self.expect("is", after="after the case expression")
        while True:
            tag = self.case_tag()
            self.expect(":", after="after the case tag")
            branches.append((tag, self.stmts(True, ("or", "otherwise", "end"))))
            if not self.take("or", "is"):
                break
        if self.take("otherwise"):
            self.expect(":", after="after otherwise")
            other = self.stmts(True, ("end",))
        self.expect("end", "case")
        return ("case", p, subject, branches, other)

    def case_tag(self):
        return self.expr(1, self._case_relation)

    def _case_relation(self):
        t = self.tok()
        if t[1] in ("=", "!=", "<", ">", "<=", ">=", "between", "within", "in"):
            return self.relational(SUBJECT)
        return ("cmp", t[2], "=", SUBJECT, self.term())  # a bare value means '= value'

    def parallel(self, p):
        every = True
        if self.take("until", "one", "completes"):
            every = False
        else:
            self.take("until", "all", "complete")
        branches = []
        while not self.at("end"):
            if not self.at("initiate", "and", "confirm"):
                self.err("in parallel holds 'initiate and confirm' statements, found %s"
                         % _show(self.tok()))  # fmt: skip
            branches.append(self.statement(True))
            self.expect(";", after="after the parallel branch")
        if len(branches) < 2:
            self.err("in parallel needs at least two branches", p)
        self.expect("end", "parallel")
        return ("par", p, every, branches)

    def continuation(self):
        if not (self.at("in", "case") and self.tok(2)[1] in ("confirmed", "not", "aborted")):
            return None
        self.i += 2
        out = {}
        while not self.at("end"):
            for words in _STATUS:
                if self.take(*words):
                    status = " ".join(words)
                    break
            else:
                self.err("expected confirmed, not confirmed or aborted, found %s"
                         % _show(self.tok()))  # fmt: skip
            self.expect(":", after="after the confirmation status")
            out[status] = self.action()
            self.expect(";", after="after the continuation action")
        self.expect("end", "case")
        return out

    def action(self):
        p = self.pos()
        for w in ("resume", "abort", "continue", "terminate"):
            if self.take(w):
                return (w, p)
        if self.take("ask", "user"):
            return ("ask user", p)
        if self.take("raise", "event"):
            return ("raise", p, self.name("an event name"))
        if self.take("restart"):
            to = self.timeout()
            mx = ev = None
            if to is None and self.take("max", "times"):
                mx = self.expr()
                ev = self.name("an event name") if self.take("raise", "event") else None
            return ("restart", p, to, mx, ev)
        self.err("expected a continuation action, found %s" % _show(self.tok()))
