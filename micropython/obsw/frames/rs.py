"""Reed-Solomon (255,223) E=16 and (255,239) E=8 of CCSDS 131.0-B: dual basis, interleaving,
virtual fill, errors-and-erasures decoding (Berlekamp-Massey, Chien search, Forney)."""

from obsw.compat import bytes_ops, const
from obsw.frames.errors import FrameLengthError, RsUncorrectableError

N = const(255)
DEPTHS = (1, 2, 3, 4, 5, 8)
_POLY = const(0x187)  # field generator F(x) = x^8 + x^7 + x^2 + x + 1
_ROOT_LOG = const(11)  # the code generator's roots are (alpha^11)^j

# CCSDS 131.0-B Annex F, the matrix T from the conventional representation (alpha^7 ... alpha^0)
# to Berlekamp's dual basis (l0 ... l7): row i is the dual-basis octet of alpha^(7-i).
_T_ROWS = (0x8D, 0xEF, 0xEC, 0x86, 0xFA, 0x99, 0xAF, 0x7B)

_tables = []  # [exp, log, to_dual, to_conventional], built on first use


def _gf_tables():
    if _tables:
        return _tables
    # exp/log to the base beta = alpha^11 (primitive, as 11 is prime to 255): the generator's
    # roots are then beta^j and the decoder is the textbook one with first root 128 - E.
    alpha = bytearray(N)
    x = 1
    for i in range(N):
        alpha[i] = x
        x <<= 1
        if x & 0x100:
            x ^= _POLY
    exp = bytearray(2 * N)
    log = bytearray(256)
    for i in range(N):
        b = alpha[(i * _ROOT_LOG) % N]
        exp[i] = exp[i + N] = b
        log[b] = i
    to_dual = bytearray(256)
    to_conv = bytearray(256)
    for v in range(256):
        d = 0
        for i in range(8):
            if v & (0x80 >> i):
                d ^= _T_ROWS[i]
        to_dual[v] = d
        to_conv[d] = v
    _tables.extend((bytes(exp), bytes(log), bytes(to_dual), bytes(to_conv)))
    return _tables


def to_dual(data):
    """Octets in the conventional representation to Berlekamp's dual basis (Annex F)."""
    return _map(data, _gf_tables()[2])


def to_conventional(data):
    """Octets in the dual basis to the conventional representation (Annex F)."""
    return _map(data, _gf_tables()[3])


def _map(data, table, fast=None):
    if fast if fast is not None else bytes_ops():
        return bytes(data).translate(table)
    out = bytearray(len(data))
    for i in range(len(data)):
        out[i] = table[data[i]]
    return bytes(out)


def _mul(a, b, exp, log):
    if a == 0 or b == 0:
        return 0
    return exp[log[a] + log[b]]


def generator(e):
    """The code generator g(x) = prod (x - beta^j), j = 128-E ... 127+E, highest degree first
    (conventional representation, monic: the first coefficient is 1)."""
    exp, log = _gf_tables()[:2]
    g = [1]
    for j in range(128 - e, 128 + e):
        root = exp[j % N]
        nxt = g + [0]
        for i in range(1, len(nxt)):
            nxt[i] ^= _mul(g[i - 1], root, exp, log)
        g = nxt
    return g


class ReedSolomon:
    """One RS code of CCSDS 131.0-B (``e`` = 16 or 8) with interleaving depth ``depth`` and
    codeblocks carrying ``length`` octets of data (the TM frame; a multiple of ``depth``, at
    most ``depth`` * (255 - 2E)): the rest of each codeword is virtual fill, never sent.

    ``encode(frame)`` gives the codeblock (frame, then the 2E * depth check symbols);
    ``decode(codeblock, erasures)`` gives ``(frame, corrected)`` with the symbols corrected
    per codeword, or raises RsUncorrectableError. Octets are in the dual basis, as sent.
    """

    def __init__(self, e=16, depth=1, length=None, fast=None):
        if e not in (8, 16):
            raise ValueError("RS error-correcting capability E is 16 or 8, not %r" % (e,))
        if depth not in DEPTHS:
            raise ValueError("RS interleaving depth is one of %s, not %r" % (DEPTHS, depth))
        self.e = e
        self.depth = depth
        self.parity = 2 * e
        self.k = N - 2 * e
        if length is None:
            length = self.k * depth
        if not depth <= length <= self.k * depth:
            raise FrameLengthError("RS codeblock data", self.k * depth, length)
        if length % depth:
            what = "RS codeblock data (a multiple of the interleaving depth %d)" % depth
            raise FrameLengthError(what, length - length % depth, length)
        self.length = length
        self.fill = self.k - length // depth  # virtual fill per codeword
        self.block_length = length + self.parity * depth
        self.fast = bytes_ops() if fast is None else fast
        self._fcr = 128 - e
        self._shift = 8 * (self.parity - 1)
        self._mask = (1 << (8 * self.parity)) - 1
        exp, log, self._dual, self._conv = _gf_tables()
        g = generator(e)[1:]  # g_{2E-1} ... g_0
        rows = []
        for fb in range(256):
            r = 0
            for c in g:
                r = (r << 8) | _mul(fb, c, exp, log)
            rows.append(r)
        self._rows = rows

    def _remainder(self, conv):
        # m(x) x^2E mod g(x) of conventional symbols, as one integer (x^(2E-1) in the top octet)
        rows = self._rows
        mask = self._mask
        shift = self._shift
        reg = 0
        for d in conv:
            reg = ((reg << 8) & mask) ^ rows[d ^ (reg >> shift)]
        return reg

    def _split(self, block):
        i = self.depth
        if i == 1:
            return [block]
        if self.fast:
            return [block[w::i] for w in range(i)]
        return [bytes(block[t] for t in range(w, len(block), i)) for w in range(i)]

    def _join(self, words, length):
        i = self.depth
        if i == 1:
            return bytes(words[0])
        out = bytearray(length)
        if self.fast:
            for w in range(i):
                out[w::i] = words[w]
        else:
            for w in range(i):
                word = words[w]
                for s in range(len(word)):
                    out[s * i + w] = word[s]
        return bytes(out)

    def encode(self, frame):
        """The codeblock of ``frame`` (``length`` octets): the frame, then its check symbols."""
        if len(frame) != self.length:
            raise FrameLengthError("RS codeblock data", self.length, len(frame))
        checks = []
        for word in self._split(frame):
            reg = self._remainder(_map(word, self._conv, self.fast))
            checks.append(_map(reg.to_bytes(self.parity, "big"), self._dual, self.fast))
        return bytes(frame) + self._join(checks, self.parity * self.depth)

    def decode(self, block, erasures=None):
        """``(frame, corrected)`` from a codeblock; ``erasures`` are octet positions in the
        codeblock known to be unreliable (each costs one check symbol, an error two).

        ``corrected`` lists the symbols corrected in each of the ``depth`` codewords."""
        if len(block) != self.block_length:
            raise FrameLengthError("RS codeblock", self.block_length, len(block))
        depth = self.depth
        per_word = [[] for _ in range(depth)]
        if erasures:
            for pos in erasures:
                if not 0 <= pos < self.block_length:
                    raise ValueError("erasure position %d outside the codeblock" % pos)
                per_word[pos % depth].append(pos // depth)
        words = self._split(block)
        corrected = []
        failed = []
        out = []
        for w in range(depth):
            conv = bytearray(_map(words[w], self._conv, self.fast))
            n = decode_word(self, conv, per_word[w])
            corrected.append(n)
            if n < 0:
                failed.append(w)
                out.append(words[w][: len(words[w]) - self.parity])
            elif n:
                out.append(_map(conv[: len(conv) - self.parity], self._dual, self.fast))
            else:
                out.append(words[w][: len(words[w]) - self.parity])
        frame = self._join(out, self.length)
        if failed:
            raise RsUncorrectableError(failed, corrected, frame)
        return frame, corrected


def decode_word(code, cw, erasures=()):
    """Correct one (shortened) codeword ``cw`` in place (a bytearray, conventional basis);
    ``erasures`` are indices into ``cw``. Returns the symbols corrected, or -1."""
    exp, log = _gf_tables()[:2]
    n = len(cw)
    nroots = code.parity
    k = n - nroots
    rem = code._remainder(memoryview(cw)[:k]) ^ int.from_bytes(bytes(cw[k:]), "big")
    if rem == 0:
        return 0  # a codeword: erased symbols, if any, were right
    if len(erasures) > nroots:
        return -1
    # Syndromes S_j = r(beta^(fcr+j)) of the remainder r(x), which has the received word's.
    fcr = code._fcr
    r = []
    while rem:
        r.append(rem & 0xFF)
        rem >>= 8
    synd = []
    for j in range(nroots):
        root = fcr + j
        s = 0
        for i in range(len(r)):
            if r[i]:
                s ^= exp[(log[r[i]] + root * i) % N]
        synd.append(s)
    # Erasure locator: prod (1 - X x) with X = beta^degree, degree = n - 1 - index.
    lam = [1] + [0] * nroots
    for idx in erasures:
        x = exp[(n - 1 - idx) % N]
        for i in range(nroots, 0, -1):
            if lam[i - 1]:
                lam[i] ^= _mul(x, lam[i - 1], exp, log)
    ne = len(erasures)
    b = lam[:]
    el = ne
    for step in range(ne, nroots):
        delta = 0
        for i in range(step + 1):
            if lam[i] and synd[step - i]:
                delta ^= exp[log[lam[i]] + log[synd[step - i]]]
        if delta == 0:
            b = [0] + b[:nroots]
            continue
        t = lam[:]
        ld = log[delta]
        for i in range(1, nroots + 1):
            if b[i - 1]:
                t[i] ^= exp[ld + log[b[i - 1]]]
        if 2 * el <= step + ne:
            el = step + 1 - el + ne
            inv = N - ld
            b = [exp[log[c] + inv] if c else 0 for c in lam]
        else:
            b = [0] + b[:nroots]
        lam = t
    deg = nroots
    while deg and not lam[deg]:
        deg -= 1
    if deg == 0 or deg > nroots:
        return -1
    # Chien search over the symbols actually present (the virtual fill cannot be in error).
    lam_log = [log[c] if c else -1 for c in lam[: deg + 1]]
    roots = []
    for p in range(n):
        s = 0
        for i in range(deg + 1):
            li = lam_log[i]
            if li >= 0:
                s ^= exp[(li - i * p) % N]
        if s == 0:
            roots.append(p)
            if len(roots) == deg:
                break
    if len(roots) != deg:
        return -1
    # Omega(x) = S(x) Lambda(x) mod x^2E; Forney: e = X^(1-fcr) Omega(X^-1) / Lambda'(X^-1).
    omega = [0] * nroots
    for i in range(nroots):
        if synd[i]:
            ls = log[synd[i]]
            for j in range(min(deg, nroots - 1 - i) + 1):
                if lam[j]:
                    omega[i + j] ^= exp[ls + log[lam[j]]]
    count = 0
    for p in roots:
        num = 0
        for i in range(nroots):
            if omega[i]:
                num ^= exp[(log[omega[i]] - i * p) % N]
        den = 0
        for i in range(1, deg + 1, 2):
            if lam[i]:
                den ^= exp[(log[lam[i]] - (i - 1) * p) % N]
        if den == 0:
            return -1
        if num == 0:
            continue
        err = exp[(log[num] - log[den] + (1 - fcr) * p) % N]
        cw[n - 1 - p] ^= err
        count += 1
    if code._remainder(memoryview(cw)[:k]) != int.from_bytes(bytes(cw[k:]), "big"):
        return -1
    return count
