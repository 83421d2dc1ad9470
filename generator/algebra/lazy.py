"""The one lazy-series engine: a power series whose coefficients are computed on demand, each
once — given terms, maps, linear combinations, Cauchy products and the relaxed (online,
packed) product of ε-series of :class:`series.Trig` sums over QQ."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from flint import fmpq_poly, fmpz, fmpz_poly

from .series import Trig

# A perturbation series Σ_i X_i ε^i whose coefficients X_i are Trig sums over QQ is made one
# order at a time, and a product c = a·b is wanted at order i as soon as a and b are known to
# order i.  Term by term, [ε^i] c = Σ_k a_k b_(i−k) costs i Trig products at order i, K²/2 in
# all.  The relaxed product (van der Hoeven) groups the pairs (k, l) with k, l ≥ 1 into squares
# [m, 2m) × [m t, m(t+1)), m = 2^p — on the diagonal (t = 1) and off it (t ≥ 2, and the
# transposed) — each multiplied as one bivariate product (Kronecker: the ε-index packed into
# the power of C with a stride the products cannot overflow) as soon as its last input is
# known, i.e. when [ε^(m(t+1))] c is first asked for.  The pairs (0, i) and (i, 0) stay term
# by term: order i may still change its inputs' coefficient i (a limit cycle's amplitude is
# fixed one order late), and :meth:`RelaxedProduct.forget` remakes just those.


class LazySeries:
    """A power series whose coefficients are computed on demand, each once and kept (until
    :meth:`forget`): the one engine of the perturbation series — the L–P kernel's forces
    (:mod:`derive.lindstedt`), a normal mode's monomials (:mod:`derive.nnm`), a limit cycle's
    ε-products (:mod:`derive.cycles`).  A coefficient is whatever the series holds: a
    :class:`Trig`, a polynomial in C of the kernel, a scalar."""

    def __init__(self) -> None:
        self.cache: dict[int, Any] = {}

    def coeff(self, i: int) -> Any:
        """The coefficient of the ``i``-th power, made once and kept."""
        if i not in self.cache:
            self.cache[i] = self.compute(i)
        return self.cache[i]

    def compute(self, i: int) -> Any:
        raise NotImplementedError

    def forget(self, i: int) -> None:
        """Coefficient ``i`` of an input changed: drop the one made from it."""
        self.cache.pop(i, None)


class Terms(LazySeries):
    """A series given term by term (``terms[i]``; the caller appends and replaces)."""

    def __init__(self, terms: list) -> None:
        super().__init__()
        self.terms = terms

    def coeff(self, i: int) -> Any:
        """``terms[i]``, as given."""
        return self.terms[i]


class Mapped(LazySeries):
    """``fn`` applied to each coefficient of ``source`` (a derivative, a factor)."""

    def __init__(self, source: LazySeries, fn: Callable[[Any], Any]) -> None:
        super().__init__()
        self.source, self.fn = source, fn

    def compute(self, i: int) -> Any:
        return self.fn(self.source.coeff(i))


class Linear(LazySeries):
    """``first + Σ c_k·node_k``: exact scalars ``c_k`` times series; ``first`` (the constant
    term, or ``None``) added to coefficient 0, ``zero`` the empty coefficient."""

    def __init__(self, terms: list[tuple[Any, LazySeries]], zero: Any,
                 first: Any = None) -> None:
        super().__init__()
        self.terms, self.zero, self.first = terms, zero, first

    def compute(self, i: int) -> Any:
        acc = self.first if i == 0 and self.first is not None else self.zero
        for c, node in self.terms:
            acc = acc + node.coeff(i) * c
        return acc


class Product(LazySeries):
    """``a · b`` by the Cauchy sum ``Σ_k a_k b_(i−k)`` (a square, ``a is b``: half the
    products), each coefficient once; ``post`` is applied to each (the odd basis' factor
    ``C² = v``: a shift).  :class:`RelaxedProduct` is its online, packed form for Trig sums."""

    def __init__(self, a: LazySeries, b: LazySeries,
                 post: Callable[[Any], Any] | None = None) -> None:
        super().__init__()
        self.a, self.b, self.post = a, b, post

    def compute(self, i: int) -> Any:
        a, b = self.a, self.b
        if a is b:
            acc = None
            for x in range((i + 1) // 2):
                term = a.coeff(x) * a.coeff(i - x)
                acc = term if acc is None else acc + term
            acc = acc * 2 if acc is not None else None
            if i % 2 == 0:
                sq = a.coeff(i // 2) * a.coeff(i // 2)
                acc = sq if acc is None else acc + sq
        else:
            acc = a.coeff(0) * b.coeff(i)
            for x in range(1, i + 1):
                acc = acc + a.coeff(x) * b.coeff(i - x)
        return acc if self.post is None else self.post(acc)


PACKED_FROM = 2
# NOTE: squares of this many orders and more are packed (Kronecker); a single pair is one Trig
# product (2 and 4 measured alike: van der Pol to order 100, 6.0–6.1 s against 6.1–6.3).


class RelaxedProduct(Product):
    """``a · b`` (``a is b``: a square), online: coefficient ``i`` may be asked for once ``a``
    and ``b`` are final to order ``i − 1`` (their coefficient ``i`` may change later:
    :meth:`forget` drops the product's coefficient ``i``, whose pairs ``(0, i)`` and ``(i, 0)``
    are remade on request; the squares use only final coefficients)."""

    def __init__(self, a: LazySeries, b: LazySeries) -> None:
        super().__init__(a, b)
        self.blocks: dict[int, list] = {}  # (part, numerator, denominator) from the squares
        self.started = 1  # squares of output index ≤ started are made

    def coeff(self, i: int) -> Trig:
        """Coefficient ``i`` of ``a · b``: the pairs ``(0, i)`` and ``(i, 0)`` term by term, the
        others from the packed squares, made as far as ``i`` needs (off QQ, the plain Cauchy
        sum); kept until :meth:`forget`."""
        if i in self.cache:
            return self.cache[i]
        a, b = self.a, self.b
        if not a.coeff(0).ground.is_rational:  # no integer packing off QQ: the Cauchy sum
            self.cache[i] = out = self.compute(i)
            return out
        while self.started < i:
            self.started += 1
            self._squares(self.started)
        a, b = self.a, self.b
        out = a.coeff(0) * b.coeff(0) if i == 0 else \
            a.coeff(0) * b.coeff(i) + a.coeff(i) * b.coeff(0)
        if i in self.blocks:
            cos, sin = _sum_pieces(self.blocks[i])
            out = Trig(out.cos_part + cos, out.sin_part + sin, out.ground)
        self.cache[i] = out
        return out

    def _squares(self, n: int) -> None:
        """The squares whose lowest output index is ``n``: ``m | n``, ``t = n/m − 1 ≥ 1``."""
        m = 1
        while 2 * m <= n:
            if n % m == 0:
                t = n // m - 1
                low, high = range(m, 2 * m), range(m * t, m * t + m)
                if t == 1:
                    self._block(low, low)
                elif self.a is self.b:
                    self._block(low, high, twice=True)
                else:
                    self._block(low, high)
                    self._block(high, low)
            m *= 2

    def _block(self, ks: range, ls: range, twice: bool = False) -> None:
        a = [self.a.coeff(k) for k in ks]
        b = [self.b.coeff(ll) for ll in ls]
        base = ks[0] + ls[0]
        if len(ks) < PACKED_FROM:
            pieces = []
            for k, x in enumerate(a):
                for m, y in enumerate(b):
                    xy = x * y
                    for part, poly in ((0, xy.cos_part), (1, xy.sin_part)):
                        if poly:
                            pieces.append((k + m, part, poly.numer(), poly.denom()))
        else:
            pieces = _block_product(a, b)
        for r, part, num, den in pieces:
            self.blocks.setdefault(base + r, []).append((part, num * 2 if twice else num, den))


def _block_product(a: list[Trig], b: list[Trig]) -> list[tuple[int, int, Any, Any]]:
    """``Σ_(k+l=r) a_k b_l`` for ``r = 0 … len(a)+len(b)−2``, as pieces ``(r, 0 for the cos
    part or 1 for the sin part, integer numerator polynomial, denominator)``.

    Each Trig is split into four parts ``C^c S^s · p(v)``, ``v = C²`` (the even and odd powers
    of C in P and R), so a product of parts is one part again, times ``v`` for ``c = c' = 1``
    and ``1 − v`` for ``s = s' = 1``.  Each part is packed over the block into one integer
    polynomial (``v^d ε^k → x^(S k + d)``, one common denominator a side) and only nonzero
    parts are multiplied: van der Pol's q_k is ``C·p(v)`` for even k and ``S·r(v)`` for odd
    k, so when every part lives on one parity of k the packing takes every other k.
    """
    da, den_a = _parts(a)
    db, den_b = _parts(b)
    length_a = max((len(c) for t in da for c in t.values()), default=1)
    length_b = max((len(c) for t in db for c in t.values()), default=1)
    S = length_a + length_b + 1  # room for a product of two parts and its factor v(1 − v)
    pa, pb = _parities(da), _parities(db)
    halved = pa is not None and pb is not None
    if not halved:
        pa = pb = None
    packed_a, packed_b = _pack_parts(da, S, pa), _pack_parts(db, S, pb)
    sums: dict[tuple, Any] = {}
    for (ca, sa), (xa, oa) in packed_a.items():
        for (cb, sb), (xb, ob) in packed_b.items():
            prod = xa * xb
            if ca and cb:
                prod = prod.left_shift(1)
            if sa and sb:
                prod = prod - prod.left_shift(1)
            key = (ca ^ cb, sa ^ sb, oa + ob)
            sums[key] = sums[key] + prod if key in sums else prod
    n_out = len(a) + len(b) - 1
    parts: list[dict] = [{} for _ in range(n_out)]
    for (c, s_, offset), poly in sorted(sums.items()):
        coeffs = poly.coeffs()
        for slot in range((len(coeffs) + S - 1) // S):
            r = offset + (2 * slot if halved else slot)
            piece = coeffs[S * slot: S * slot + S]
            if any(piece):
                old = parts[r].get((c, s_))
                parts[r][(c, s_)] = piece if old is None else _add_lists(old, piece)
    den = den_a * den_b
    out = []
    for r, part in enumerate(parts):
        for which, even, odd in ((0, (0, 0), (1, 0)), (1, (0, 1), (1, 1))):
            if even in part or odd in part:
                out.append((r, which, fmpz_poly(_interleave(part.get(even, []),
                                                             part.get(odd, []))), den))
    return out


def _sum_pieces(pieces: list) -> tuple[Any, Any]:
    """``(cos, sin)`` polynomials of ``(part, numerator, denominator)`` pieces: over one common
    denominator, reduced once (not at each partial sum)."""
    out = []
    for which in (0, 1):
        mine = [(num, den) for part, num, den in pieces if part == which]
        common = fmpz(1)
        for _, den in mine:
            common = common.lcm(den)
        total = fmpz_poly([])
        for num, den in mine:
            total += num * (common // den)
        out.append(fmpq_poly(total, common))
    return out[0], out[1]


def _parts(terms: list[Trig]) -> tuple[list[dict], Any]:
    """Each Trig's nonzero parts ``{(c, s): integer coefficients in v}`` over one denominator."""
    den = fmpz(1)
    for t in terms:
        den = den.lcm(t.cos_part.denom()).lcm(t.sin_part.denom())
    out = []
    for t in terms:
        split = {}
        for s_, p in ((0, t.cos_part), (1, t.sin_part)):
            if p:
                c = (p.numer() * (den // p.denom())).coeffs()
                for parity in (0, 1):
                    if any(c[parity::2]):
                        split[(parity, s_)] = c[parity::2]
        out.append(split)
    return out, den


def _parities(side: list[dict]) -> dict | None:
    """``{part: parity of k}`` when each part is nonzero on one parity of k only, else None."""
    found: dict = {}
    for k, split in enumerate(side):
        for key in split:
            if found.setdefault(key, k % 2) != k % 2:
                return None
    return found


def _pack_parts(side: list[dict], S: int, parities: dict | None) -> dict:
    """``{part: (packed polynomial, offset of its first k)}``, every other k when halved."""
    out = {}
    keys = sorted({key for split in side for key in split})
    for key in keys:
        offset = parities[key] if parities is not None else 0
        step = 2 if parities is not None else 1
        coeffs: list = []
        for k in range(offset, len(side), step):
            c = side[k].get(key, [])
            coeffs += c
            coeffs += [0] * (S - len(c))
        out[key] = (fmpz_poly(coeffs), offset)
    return out


def _add_lists(x: list, y: list) -> list:
    if len(x) < len(y):
        x, y = y, x
    return [u + w for u, w in zip(x, y, strict=False)] + x[len(y):]


def _interleave(even: list, odd: list) -> list:
    out = [0] * max(2 * len(even) - 1, 2 * len(odd), 0)
    out[0:2 * len(even):2] = even
    out[1:2 * len(odd):2] = odd
    return out


