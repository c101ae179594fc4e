"""CFDP across passes: transactions suspended at LOS and resumed at AOS.

A class 2 transfer larger than one pass would otherwise run its timers out while the link is
gone and be cancelled (or restarted from zero). ``PassHold(entity)`` takes the contact edges of
``obsw.frames.contact`` (or the ground's own pass prediction): at LOS it suspends every active
transaction of the entity (CFDP's Suspend.request: nothing is sent, every timer frozen with the
time it had left), at AOS it resumes those it suspended, so each continues where it stopped
and its timers run on from where they were. A transaction the user suspended stays suspended.
"""

from obsw.frames.contact import AOS, LOS


class PassHold:
    """Suspend out of contact, resume at AOS (see the module text)."""

    def __init__(self, entity):
        self.entity = entity
        self.held = []  # the transactions this hold suspended (tid, role keys)
        self.suspends = 0
        self.resumes = 0

    def update(self, in_contact, now):
        """Call with the contact state each cycle: out of contact, every active transaction
        (one started since too) is suspended; in contact, those it suspended are resumed."""
        if in_contact:
            if self.held:
                self.aos(now)
        else:
            self.los(now)

    def edge(self, edge, now):
        """The same driven by edges (``AOS``, ``LOS``) rather than the state."""
        if edge == LOS:
            self.los(now)
        elif edge == AOS:
            self.aos(now)

    def los(self, now):
        for key, tx in list(self.entity.tx.items()):
            if not tx.done and not tx.suspended and tx.suspend(now):
                self.held.append(key)
                self.suspends += 1

    def aos(self, now):
        held, self.held = self.held, []
        for key in held:
            tx = self.entity.tx.get(key)
            if tx is not None and tx.resume(now):
                self.resumes += 1
