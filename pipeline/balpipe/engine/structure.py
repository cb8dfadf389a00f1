"""Structural decomposition of the constraint Jacobian and the triangular solves it allows.

The sparsity pattern of Phi_q (free coordinates only) is put in block lower-triangular form
(Dulmage-Mendelsohn fine decomposition, Duff and Reid 1978; Pothen and Fan 1990): a perfect
matching of rows to columns by augmenting paths (:func:`maximum_matching`; Duff's MC21), then
the strongly connected components of the graph "row r uses the column matched to row s" in
topological order (:func:`strong_components`; Tarjan 1972). Both run in pure Python over lists:
for the patterns of planar mechanisms (tens of rows) that is far cheaper than building sparse
matrices for scipy's csgraph, and the result does not depend on which matching is found (the
blocks are unique as sets; each block's columns are taken in ascending order). A square system
Phi_q x = b is then solved block by block by forward substitution, and Phi_q^T lambda = c by
backward substitution; det Phi_q is the product of the diagonal blocks' determinants, so Phi_q
is regular exactly when every diagonal block is.

For an open chain with driven joints every block is 1 x 1: the angles follow from the driver
rows, the positions from the revolute rows, one sample-wise division each. Blocks that are
independent of each other are grouped in levels and solved together (one gather per level).
The decomposition depends only on the pattern, so it is cached by pattern
(:func:`decompose`): stages and designs with the same topology share it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .vectorised import Vectorised


@dataclass
class Step:
    """One level of a triangular solve: a group of 1 x 1 blocks, or one k x k block."""

    eq: np.ndarray  # equations (rows of the right-hand side)
    unk: np.ndarray  # unknowns
    diag: np.ndarray  # 1x1 group: (g,) pivot slots; k x k block: (k, k) slots (pad slot for zeros)
    off_slots: np.ndarray  # (g, w) Jacobian slots of the couplings to earlier unknowns (padded)
    off_unk: np.ndarray  # (g, w) those unknowns (padded with the zero row)
    square: bool  # a k x k block (k > 1)
    block: int = -1  # k x k block: its index in Decomposition.blocks


@dataclass
class Plan:
    """Steps of a forward (Phi_q x = b) or backward (Phi_q^T lambda = c) substitution."""

    steps: list[Step]
    n_unknowns: int
    transposed: bool


@dataclass
class Decomposition:
    """Block-triangular form of a square constraint Jacobian."""

    forward: Plan
    backward: Plan
    explicit: bool  # every block 1 x 1 and linear in its unknown: positions without Newton
    pivots_constant: bool  # every 1 x 1 pivot is a constant entry
    blocks: list[tuple[list[int], list[int]]]  # (rows, free columns) per block, in order
    pad: int  # the zero slot
    square_blocks: list[tuple[int, np.ndarray]]  # (block index, (k, k) slots) of the k x k blocks
    # explicit systems: (equations, unknowns, pivot slots) per level, angles then positions; for
    # the angles the equations index the angle rows (Vectorised.arow)
    angle_steps: list[tuple[np.ndarray, np.ndarray, np.ndarray]]
    position_steps: list[tuple[np.ndarray, np.ndarray, np.ndarray]]


def pattern_key(vz: Vectorised) -> tuple:
    """What the decomposition depends on: sizes, the structural entries and which entries are
    constant, and each row's primitive type (linearity)."""
    return (vz.m, vz.ncol, vz.rows.tobytes(), vz.cols.tobytes(), vz.structural.tobytes(),
            np.isnan(vz.const).tobytes(), _row_kind(vz).tobytes())


def _row_kind(vz: Vectorised) -> np.ndarray:
    kind = np.zeros(vz.m, dtype=np.int8)  # 0 revolute, 1 angle, 2 projection
    kind[vz.arow] = 1
    kind[vz.prow] = 2
    return kind


def decompose(vz: Vectorised) -> Decomposition | None:
    """The block-triangular decomposition of ``vz``'s Jacobian, or None when it is not square
    or structurally singular (the general dense path handles those)."""
    return _decompose_cached(pattern_key(vz), vz)


_CACHE: dict[tuple, Decomposition | None] = {}


def _decompose_cached(key: tuple, vz: Vectorised) -> Decomposition | None:
    if key not in _CACHE:
        if len(_CACHE) > 256:
            _CACHE.clear()
        _CACHE[key] = _decompose(vz)
    return _CACHE[key]


def _decompose(vz: Vectorised) -> Decomposition | None:
    m, n = vz.m, vz.ncol - 3
    if m != n or m == 0:
        return None
    rows_l, cols_l, struct_l = vz.rows.tolist(), vz.cols.tolist(), vz.structural.tolist()
    row_entries: list[list[tuple[int, int]]] = [[] for _ in range(m)]  # (column, slot) per row
    col_entries: list[list[tuple[int, int]]] = [[] for _ in range(n)]  # (row, slot) per column
    slot_of: dict[tuple[int, int], int] = {}
    for s, (r, c, st) in enumerate(zip(rows_l, cols_l, struct_l)):
        if st and c >= 3:
            c -= 3
            if (r, c) in slot_of:  # two entries on one (row, column): not expected
                return None
            slot_of[r, c] = s
            row_entries[r].append((c, s))
            col_entries[c].append((r, s))
    adj = [[c for c, _ in e] for e in row_entries]
    match = maximum_matching(adj, n)  # column matched to each row
    if -1 in match:
        return None  # structurally singular
    row_of_col = [0] * n
    for r, c in enumerate(match):
        row_of_col[c] = r
    # row r -> row s when r uses the column matched to s; components in topological order
    members = strong_components([[row_of_col[c] for c in a] for a in adj])
    nblk = len(members)
    label = [0] * m
    for b, rows in enumerate(members):
        for r in rows:
            label[r] = b
    deps: list[set[int]] = [set() for _ in range(nblk)]  # blocks whose unknowns a block uses
    for r in range(m):
        lr = label[r]
        for c in adj[r]:
            b2 = label[row_of_col[c]]
            if b2 != lr:
                deps[lr].add(b2)
    # each block's columns in ascending order: the decomposition does not depend on which
    # maximum matching was found (the blocks, as sets, are unique)
    bcols = [sorted(match[r] for r in rows) for rows in members]
    blocks = [(members[b], bcols[b]) for b in range(nblk)]
    pad = vz.nnz
    kind = _row_kind(vz).tolist()
    rdeps: list[list[int]] = [[] for _ in range(nblk)]
    for b in range(nblk):
        for b2 in sorted(deps[b]):
            rdeps[b2].append(b)

    def build(transposed: bool) -> Plan:
        # forward: equations = rows, unknowns = columns; backward: the other way round
        level = [0] * nblk
        if not transposed:
            for b in range(nblk):
                level[b] = 1 + max((level[d] for d in deps[b]), default=-1)
            seq = range(nblk)
        else:
            for b in range(nblk - 1, -1, -1):
                level[b] = 1 + max((level[d] for d in rdeps[b]), default=-1)
            seq = range(nblk - 1, -1, -1)
        groups: dict[int, list[int]] = {}
        for b in seq:
            groups.setdefault(level[b], []).append(b)
        steps = []
        for lev in sorted(groups):
            eqs, unks, piv, offs = [], [], [], []
            for b in groups[lev]:
                if len(members[b]) != 1:
                    continue
                r = members[b][0]
                c = match[r]
                if not transposed:
                    eqs.append(r)
                    unks.append(c)
                    offs.append([(s, cc) for cc, s in row_entries[r] if cc != c])
                else:
                    eqs.append(c)
                    unks.append(r)
                    offs.append([(s, rr) for rr, s in col_entries[c] if rr != r])
                piv.append(slot_of[r, c])
            if eqs:
                steps.append(_step(eqs, unks, np.array(piv, dtype=np.intp), offs, pad, n, False))
            for b in groups[lev]:
                if len(members[b]) == 1:
                    continue
                rows, cols = members[b], bcols[b]
                rset, cset = set(rows), set(cols)
                diag = square_diag[b]
                if not transposed:
                    offs = [[(s, cc) for cc, s in row_entries[r] if cc not in cset] for r in rows]
                    steps.append(_step(rows, cols, diag, offs, pad, n, True, b))
                else:
                    offs = [[(s, rr) for rr, s in col_entries[c] if rr not in rset] for c in cols]
                    steps.append(_step(cols, rows, diag.T.copy(), offs, pad, n, True, b))
        return Plan(steps, n, transposed)

    square_diag: dict[int, np.ndarray] = {}
    square_blocks = []
    for b, (rows, cols) in enumerate(blocks):
        if len(rows) > 1:
            square_diag[b] = np.array([[slot_of.get((r, c), pad) for c in cols] for r in rows], dtype=np.intp)
            square_blocks.append((b, square_diag[b]))

    explicit = all(len(rows) == 1 and (kind[rows[0]] == 1 or cols[0] % 3 != 2) for rows, cols in blocks)
    const = vz.const
    pivots_constant = all(len(rows) > 1 or not math.isnan(const[slot_of[rows[0], cols[0]]]) for rows, cols in blocks)
    forward = build(False)
    angle_steps, position_steps = [], []
    if explicit:
        where = {r: k for k, r in enumerate(vz.arow.tolist())}
        for st in forward.steps:
            ang = st.unk % 3 == 2
            if ang.any():
                eq = np.array([where[r] for r in st.eq[ang].tolist()], dtype=np.intp)
                angle_steps.append((eq, st.unk[ang], st.diag[ang]))
            if not ang.all():
                position_steps.append((st.eq[~ang], st.unk[~ang], st.diag[~ang]))
    return Decomposition(forward, build(True), explicit, pivots_constant, blocks, pad, square_blocks,
                         angle_steps, position_steps)


def _step(eqs: list[int], unks: list[int], diag: np.ndarray, offs: list[list[tuple[int, int]]], pad: int, n: int,
          square: bool, block: int = -1) -> Step:
    w = max((len(o) for o in offs), default=0)
    off_slots = [[s for s, _ in o] + [pad] * (w - len(o)) for o in offs]
    off_unk = [[u for _, u in o] + [n] * (w - len(o)) for o in offs]
    return Step(np.array(eqs, dtype=np.intp), np.array(unks, dtype=np.intp), diag,
                np.array(off_slots, dtype=np.intp).reshape(len(offs), w),
                np.array(off_unk, dtype=np.intp).reshape(len(offs), w), square, block)


def maximum_matching(adj: list[list[int]], n: int) -> list[int]:
    """A maximum matching of the rows of a pattern to its ``n`` columns (``adj[r]``: the columns
    of row r), as the column matched to each row (-1 for a row left unmatched: the pattern is
    then structurally singular, its structural rank the number of matched rows). Augmenting
    paths (Kuhn 1955; Duff 1981, algorithm MC21) by a depth-first search without recursion,
    after a cheap greedy assignment; rows and columns tried in the order given: deterministic.
    O(rows x entries), nothing for the patterns of planar mechanisms."""
    m = len(adj)
    row_col = [-1] * m
    col_row = [-1] * n
    for r, a in enumerate(adj):  # cheap assignment first
        for c in a:
            if col_row[c] < 0:
                col_row[c], row_col[r] = r, c
                break
    for r in range(m):
        if row_col[r] >= 0:
            continue
        seen = [False] * n
        path, pos = [r], [0]  # rows on the path, next column to try
        via: list[int] = []  # columns taken
        while path:
            u = path[-1]
            a = adj[u]
            p = pos[-1]
            if p == len(a):
                path.pop(), pos.pop()
                if via:
                    via.pop()
                continue
            c = a[p]
            pos[-1] = p + 1
            if seen[c]:
                continue
            seen[c] = True
            via.append(c)
            w = col_row[c]
            if w < 0:  # a free column: augment along the path
                for u2, c2 in zip(path, via):
                    row_col[u2], col_row[c2] = c2, u2
                break
            path.append(w)
            pos.append(0)
        # no augmenting path from r: r stays unmatched (Kuhn: it never gets one later)
    return row_col


def strong_components(succ: list[list[int]]) -> list[list[int]]:
    """Strongly connected components of the graph with successors ``succ[v]`` (Tarjan 1972,
    without recursion), each as a sorted list, every component after those it reaches: for
    "row r uses the unknown of row s" an order in which each block comes after those it needs.
    Deterministic (vertices and successors taken in the order given)."""
    nv = len(succ)
    index = [-1] * nv
    low = [0] * nv
    on = [False] * nv
    stack: list[int] = []
    comps: list[list[int]] = []
    counter = 0
    for s in range(nv):
        if index[s] >= 0:
            continue
        index[s] = low[s] = counter
        counter += 1
        stack.append(s)
        on[s] = True
        work = [[s, 0]]
        while work:
            frame = work[-1]
            v, p = frame
            nb = succ[v]
            if p < len(nb):
                frame[1] = p + 1
                w = nb[p]
                if index[w] < 0:
                    index[w] = low[w] = counter
                    counter += 1
                    stack.append(w)
                    on[w] = True
                    work.append([w, 0])
                elif on[w] and index[w] < low[v]:
                    low[v] = index[w]
                continue
            work.pop()
            if work:
                u = work[-1][0]
                if low[v] < low[u]:
                    low[u] = low[v]
            if low[v] == index[v]:
                comp = []
                while True:
                    w = stack.pop()
                    on[w] = False
                    comp.append(w)
                    if w == v:
                        break
                comps.append(sorted(comp))
    return comps


def solve(plan: Plan, vals: np.ndarray, rhs: np.ndarray, inverses: dict[int, np.ndarray], offset: int = 0,
          out: np.ndarray | None = None) -> np.ndarray:
    """Solve the triangular system of ``plan`` with Jacobian values ``vals`` (nnz + 1, N) (last
    row zero), the inverses of its k x k diagonal blocks (:func:`invert_blocks`) and right-hand
    side ``rhs`` (equations, N). Returns (offset + n + 1, N): ``offset`` zero rows, the n
    unknowns, a zero row (padding); written into ``out`` when given (zero, that shape: a
    chunk's columns of a larger array)."""
    N = rhs.shape[1]
    U = np.zeros((offset + plan.n_unknowns + 1, N)) if out is None else out
    for st in plan.steps:
        b = rhs[st.eq]
        if st.off_slots.shape[1]:
            b = b - np.einsum("gwn,gwn->gn", vals[st.off_slots], U[st.off_unk + offset])
        if not st.square:
            U[st.unk + offset] = b / vals[st.diag]
        else:
            inv = inverses[st.block]
            U[st.unk + offset] = np.einsum("ban,bn->an" if plan.transposed else "abn,bn->an", inv, b)
    return U


_LAPACK_SAMPLES = 300  # below this many samples (or from k = 7) LAPACK per matrix is faster


def inverse(A: np.ndarray) -> np.ndarray:
    """Inverses of a stack of small matrices laid out (k, k, N). Few samples or larger blocks:
    LAPACK's LU per matrix (:func:`numpy.linalg.inv`; its fixed cost is a few microseconds);
    otherwise Gauss-Jordan elimination with partial pivoting, vectorised over the N samples (for
    k of a few units and thousands of samples much faster than LAPACK called per matrix;
    ``benchmarks/bench_inverse.py`` measures the crossing). A singular matrix gives non-finite
    values."""
    k, _, N = A.shape
    if N <= _LAPACK_SAMPLES or k >= 7:
        try:
            return np.linalg.inv(A.transpose(2, 0, 1)).transpose(1, 2, 0)
        except np.linalg.LinAlgError:  # an exactly singular sample: non-finite values, as below
            pass
    return _gauss_jordan(A)


def _gauss_jordan(A: np.ndarray) -> np.ndarray:
    """:func:`inverse` by Gauss-Jordan elimination vectorised over the samples."""
    k, _, N = A.shape
    M = np.empty((k, 2 * k, N))
    M[:, :k] = A
    M[:, k:] = np.eye(k)[:, :, None]
    ar = np.arange(N)
    with np.errstate(divide="ignore", invalid="ignore"):
        for j in range(k):
            p = j + np.argmax(np.abs(M[j:, j, :]), axis=0)
            if np.any(p != j):
                rowp = M[p, :, ar]  # (N, 2k)
                M[p, :, ar] = M[j].T
                M[j] = rowp.T
            M[j] /= M[j, j].copy()
            for i in range(k):
                if i != j:
                    M[i] -= M[i, j].copy() * M[j]
    return M[:, k:]


def invert_blocks(dec: Decomposition, vals: np.ndarray) -> dict[int, np.ndarray]:
    """Inverses (k, k, N) of the k x k diagonal blocks, by block index. The blocks of one size
    are inverted in one call (a ladder of loops has as many blocks as loops), each sample of
    each block by the same operations as alone: the same inverses."""
    by_size: dict[int, list[tuple[int, np.ndarray]]] = {}
    for b, diag in dec.square_blocks:
        by_size.setdefault(diag.shape[0], []).append((b, diag))
    out: dict[int, np.ndarray] = {}
    N = vals.shape[1]
    per_call = max(1, _STACKED // max(N, 1))  # blocks per call: a bounded stack whatever N
    for k, same in by_size.items():
        for start in range(0, len(same), per_call):
            _invert_group(vals, same[start : start + per_call], k, N, out)
    return out


_STACKED = 16384  # block samples inverted in one call at most


def _invert_group(vals: np.ndarray, group: list[tuple[int, np.ndarray]], k: int, N: int,
                  out: dict[int, np.ndarray]) -> None:
    """The inverses of ``group``'s k x k blocks (index, slots), in one call, into ``out``."""
    if len(group) == 1:
        b, diag = group[0]
        out[b] = inverse(vals[diag])
        return
    slots = np.stack([diag for _, diag in group], axis=2)  # (k, k, blocks)
    stacked = vals[slots].reshape(k, k, -1)  # samples of block 0, then block 1, ...
    if N <= _LAPACK_SAMPLES or k >= 7:
        try:
            inv = np.linalg.inv(stacked.transpose(2, 0, 1)).transpose(1, 2, 0)
        except np.linalg.LinAlgError:  # an exactly singular sample: each block alone, as inverse() does
            out.update({b: inverse(vals[diag]) for b, diag in group})
            return
    else:
        inv = _gauss_jordan(stacked)
    for i, (b, _) in enumerate(group):
        out[b] = inv[:, :, i * N : (i + 1) * N]


def block_sigma_min(dec: Decomposition, vals: np.ndarray, inverses: dict[int, np.ndarray]) -> np.ndarray:
    """A lower bound of the smallest singular value of the diagonal blocks, per sample (N,):
    |pivot| for a 1 x 1 block, 1 / |B^-1|_F for a k x k one. Phi_q is singular exactly when a
    block is, and cond(Phi_q) >= max|entry| / sigma_min(block) (a diagonal block's inverse is a
    block of the inverse of a block-triangular matrix)."""
    out: np.ndarray | None = None
    for st in dec.forward.steps:
        if not st.square:
            s = np.abs(vals[st.diag]).min(axis=0)
        else:
            with np.errstate(invalid="ignore"):
                s = 1.0 / np.sqrt(np.einsum("abn,abn->n", inverses[st.block], inverses[st.block]))
        out = s if out is None else np.minimum(out, s)
    if out is None:
        raise ValueError("a decomposition without diagonal blocks has no smallest singular value")
    return out
