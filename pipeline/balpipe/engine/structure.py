"""Structural decomposition of the constraint Jacobian and the triangular solves it allows.

The sparsity pattern of Phi_q (free coordinates only) is put in block lower-triangular form
(Dulmage-Mendelsohn fine decomposition, Duff and Reid 1978; Pothen and Fan 1990): a maximum
bipartite matching of rows to columns (:func:`scipy.sparse.csgraph.maximum_bipartite_matching`),
then the strongly connected components of the graph "row r uses the column matched to row s"
(:func:`scipy.sparse.csgraph.connected_components`), in topological order. A square system
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

from dataclasses import dataclass
from functools import lru_cache

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
    from scipy.sparse import csr_matrix
    from scipy.sparse.csgraph import connected_components, maximum_bipartite_matching

    m, n = vz.m, vz.ncol - 3
    if m != n or m == 0:
        return None
    free = vz.structural & (vz.cols >= 3)
    slots = np.flatnonzero(free)
    R, Cl = vz.rows[slots], vz.cols[slots] - 3
    slot_of = {(int(r), int(c)): int(s) for r, c, s in zip(R, Cl, slots)}
    if len(slot_of) != len(slots):  # two entries on one (row, column): not expected
        return None
    P = csr_matrix((np.ones(len(R)), (R, Cl)), shape=(m, n))
    match = maximum_bipartite_matching(P, perm_type="column")  # column matched to each row
    if np.any(match < 0):
        return None  # structurally singular
    row_of_col = np.empty(n, dtype=np.intp)
    row_of_col[match] = np.arange(m)
    # row r -> row s when r uses the column matched to s
    G = csr_matrix((np.ones(len(R)), (R, row_of_col[Cl])), shape=(m, m))
    nblk, label = connected_components(G, directed=True, connection="strong")
    members = [sorted(np.flatnonzero(label == b).tolist()) for b in range(nblk)]
    row_entries: dict[int, list[tuple[int, int]]] = {r: [] for r in range(m)}
    col_entries: dict[int, list[tuple[int, int]]] = {c: [] for c in range(n)}
    for r, c, s in zip(R.tolist(), Cl.tolist(), slots.tolist()):
        row_entries[r].append((c, s))
        col_entries[c].append((r, s))
    deps = [set() for _ in range(nblk)]  # blocks whose unknowns a block uses
    for r in range(m):
        for c, _ in row_entries[r]:
            b2 = label[row_of_col[c]]
            if b2 != label[r]:
                deps[label[r]].add(int(b2))
    order = _topological(deps)
    blocks = [(members[b], [int(match[r]) for r in members[b]]) for b in order]
    pad = vz.nnz
    kind = _row_kind(vz)

    def build(transposed: bool) -> Plan:
        # forward: equations = rows, unknowns = columns; backward: the other way round
        level: dict[int, int] = {}
        seq = order if not transposed else order[::-1]
        rdeps = [set() for _ in range(nblk)]
        for b in range(nblk):
            for b2 in deps[b]:
                rdeps[b2].add(b)
        dep = deps if not transposed else rdeps
        for b in seq:
            level[b] = 1 + max((level[d] for d in dep[b]), default=-1)
        groups: dict[int, list[int]] = {}
        for b in seq:
            groups.setdefault(level[b], []).append(b)
        steps = []
        for lev in sorted(groups):
            singles = [b for b in groups[lev] if len(members[b]) == 1]
            if singles:
                eqs, unks, piv, offs = [], [], [], []
                for b in singles:
                    r = members[b][0]
                    c = int(match[r])
                    if not transposed:
                        eqs.append(r), unks.append(c)
                        offs.append([(s, cc) for cc, s in row_entries[r] if cc != c])
                    else:
                        eqs.append(c), unks.append(r)
                        offs.append([(s, rr) for rr, s in col_entries[c] if rr != r])
                    piv.append(slot_of[(r, c)])
                steps.append(_step(eqs, unks, np.array(piv, dtype=np.intp), offs, pad, n, False))
            for b in groups[lev]:
                if len(members[b]) == 1:
                    continue
                rows, cols = members[b], [int(match[r]) for r in members[b]]
                k = len(rows)
                diag = np.full((k, k), pad, dtype=np.intp)
                for a, r in enumerate(rows):
                    for bb, c in enumerate(cols):
                        diag[a, bb] = slot_of.get((r, c), pad)
                if not transposed:
                    offs = [[(s, cc) for cc, s in row_entries[r] if cc not in cols] for r in rows]
                    steps.append(_step(rows, cols, diag, offs, pad, n, True, position[b]))
                else:
                    offs = [[(s, rr) for rr, s in col_entries[c] if rr not in rows] for c in cols]
                    steps.append(_step(cols, rows, diag.T.copy(), offs, pad, n, True, position[b]))
        return Plan(steps, n, transposed)

    position = {b: k for k, b in enumerate(order)}
    square_blocks = []
    for k, (rows, cols) in enumerate(blocks):
        if len(rows) > 1:
            square_blocks.append((k, np.array([[slot_of.get((r, c), pad) for c in cols] for r in rows], dtype=np.intp)))

    explicit = all(len(rows) == 1 and (kind[rows[0]] == 1 or cols[0] % 3 != 2) for rows, cols in blocks)
    pivots_constant = all(
        len(rows) > 1 or not np.isnan(vz.const[slot_of[(rows[0], cols[0])]]) for rows, cols in blocks
    )
    forward = build(False)
    angle_steps, position_steps = [], []
    if explicit:
        where = {int(r): k for k, r in enumerate(vz.arow)}
        for st in forward.steps:
            ang = st.unk % 3 == 2
            if ang.any():
                eq = np.array([where[int(r)] for r in st.eq[ang]], dtype=np.intp)
                angle_steps.append((eq, st.unk[ang], st.diag[ang]))
            if (~ang).any():
                position_steps.append((st.eq[~ang], st.unk[~ang], st.diag[~ang]))
    return Decomposition(forward, build(True), explicit, pivots_constant, blocks, pad, square_blocks,
                         angle_steps, position_steps)


def _step(eqs, unks, diag, offs, pad: int, n: int, square: bool, block: int = -1) -> Step:
    w = max((len(o) for o in offs), default=0)
    off_slots = np.full((len(offs), w), pad, dtype=np.intp)
    off_unk = np.full((len(offs), w), n, dtype=np.intp)
    for a, o in enumerate(offs):
        for b, (s, u) in enumerate(o):
            off_slots[a, b] = s
            off_unk[a, b] = u
    return Step(np.array(eqs, dtype=np.intp), np.array(unks, dtype=np.intp), diag, off_slots, off_unk, square, block)


def _topological(deps: list[set[int]]) -> list[int]:
    """Blocks ordered so that every block comes after those it depends on."""
    from graphlib import TopologicalSorter

    return list(TopologicalSorter({b: deps[b] for b in range(len(deps))}).static_order())


def solve(plan: Plan, vals: np.ndarray, rhs: np.ndarray, inverses: dict[int, np.ndarray], offset: int = 0) -> np.ndarray:
    """Solve the triangular system of ``plan`` with Jacobian values ``vals`` (nnz + 1, N) (last
    row zero), the inverses of its k x k diagonal blocks (:func:`invert_blocks`) and right-hand
    side ``rhs`` (equations, N). Returns (offset + n + 1, N): ``offset`` zero rows, the n
    unknowns, a zero row (padding)."""
    N = rhs.shape[1]
    U = np.zeros((offset + plan.n_unknowns + 1, N))
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
    """Inverses (k, k, N) of the k x k diagonal blocks, by block index."""
    return {b: inverse(vals[diag]) for b, diag in dec.square_blocks}


def block_sigma_min(dec: Decomposition, vals: np.ndarray, inverses: dict[int, np.ndarray]) -> np.ndarray:
    """A lower bound of the smallest singular value of the diagonal blocks, per sample (N,):
    |pivot| for a 1 x 1 block, 1 / |B^-1|_F for a k x k one. Phi_q is singular exactly when a
    block is, and cond(Phi_q) >= max|entry| / sigma_min(block) (a diagonal block's inverse is a
    block of the inverse of a block-triangular matrix)."""
    out = None
    for st in dec.forward.steps:
        if not st.square:
            s = np.abs(vals[st.diag]).min(axis=0)
        else:
            with np.errstate(invalid="ignore"):
                s = 1.0 / np.sqrt(np.einsum("abn,abn->n", inverses[st.block], inverses[st.block]))
        out = s if out is None else np.minimum(out, s)
    return out
