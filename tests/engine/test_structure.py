"""The structural decomposition of the constraint Jacobian (engine/structure.py): the pure-Python
maximum matching and strongly connected components against scipy's csgraph as the reference, on
seeded random patterns (regular and structurally singular) and on every spec's models."""

from __future__ import annotations

import glob

import numpy as np
import pytest
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import connected_components, maximum_bipartite_matching, structural_rank

from balpipe import registry
from balpipe.engine import compile_model
from balpipe.engine.structure import _decompose, maximum_matching, strong_components
from balpipe.engine.vectorised import vectorise
from balpipe.loader import load


def _random_pattern(rng: np.random.Generator, m: int, n: int, density: float, square_diag: bool) -> list[list[int]]:
    """Columns of each row, in a shuffled order (the matching must not rely on sorted input)."""
    P = rng.random((m, n)) < density
    if square_diag:  # a hidden perfect matching: a permuted diagonal
        P[np.arange(min(m, n)), rng.permutation(n)[: min(m, n)]] = True
    adj = []
    for r in range(m):
        cols = np.flatnonzero(P[r])
        adj.append(rng.permutation(cols).tolist())
    return adj


def _csr(adj: list[list[int]], m: int, n: int) -> csr_matrix:
    R = [r for r, a in enumerate(adj) for _ in a]
    C = [c for a in adj for c in a]
    return csr_matrix((np.ones(len(R)), (R, C)), shape=(m, n))


def _check_matching(adj, match, n):
    used = [c for c in match if c >= 0]
    assert len(used) == len(set(used)), "a column matched twice"
    for r, c in enumerate(match):
        assert c == -1 or c in adj[r], "a row matched to a column it does not use"
    assert all(0 <= c < n for c in used)


def _cases():
    rng = np.random.default_rng(20261201)
    out = []
    for k in range(300):
        m = int(rng.integers(1, 25))
        n = m if k % 3 else int(rng.integers(1, 25))  # mostly square, some rectangular
        density = float(rng.uniform(0.03, 0.4))
        out.append(_random_pattern(rng, m, n, density, square_diag=bool(k % 2)) + [n])
    return out


@pytest.mark.parametrize("case", range(300))
def test_matching_has_scipys_cardinality(case):
    *adj, n = _CASES[case]
    m = len(adj)
    match = maximum_matching(adj, n)
    _check_matching(adj, match, n)
    ref = maximum_bipartite_matching(_csr(adj, m, n), perm_type="column")
    assert sum(c >= 0 for c in match) == int((ref >= 0).sum()) == structural_rank(_csr(adj, m, n))


_CASES = _cases()


def _square_regular_cases(count: int, seed: int):
    rng = np.random.default_rng(seed)
    for _ in range(count):
        m = int(rng.integers(1, 30))
        yield _random_pattern(rng, m, m, float(rng.uniform(0.02, 0.3)), square_diag=True)


@pytest.mark.parametrize("adj", list(_square_regular_cases(200, 7)))
def test_blocks_are_scipys_partition_in_topological_order(adj):
    m = len(adj)
    match = maximum_matching(adj, m)
    assert -1 not in match  # a hidden perfect matching exists
    row_of_col = [0] * m
    for r, c in enumerate(match):
        row_of_col[c] = r
    succ = [[row_of_col[c] for c in a] for a in adj]
    comps = strong_components(succ)
    # a partition of the rows, each block sorted
    assert sorted(r for b in comps for r in b) == list(range(m))
    assert all(b == sorted(b) for b in comps)
    # the same partition as scipy's (blocks are unique; scipy's own matching as the reference)
    ref_match = maximum_bipartite_matching(_csr(adj, m, m), perm_type="column")
    ref_row_of_col = np.empty(m, dtype=int)
    ref_row_of_col[ref_match] = np.arange(m)
    R = [r for r, a in enumerate(adj) for _ in a]
    S = [int(ref_row_of_col[c]) for a in adj for c in a]
    nblk, label = connected_components(csr_matrix((np.ones(len(R)), (R, S)), shape=(m, m)), directed=True,
                                       connection="strong")
    ref = sorted(sorted(np.flatnonzero(label == b).tolist()) for b in range(nblk))
    assert sorted(comps) == ref
    # topological: a row uses only columns of its own block or of earlier blocks
    block_of_col = {}
    for k, b in enumerate(comps):
        for r in b:
            block_of_col[match[r]] = k
    for k, b in enumerate(comps):
        for r in b:
            assert all(block_of_col[c] <= k for c in adj[r])
    # the block's columns are the same set whichever maximum matching was found
    for b in comps:
        assert sorted(match[r] for r in b) == sorted(int(ref_match[r]) for r in b)


def test_matching_and_components_are_deterministic():
    for adj in _square_regular_cases(20, 11):
        m = len(adj)
        a = maximum_matching(adj, m)
        assert a == maximum_matching([list(x) for x in adj], m)
        succ = [[a.index(c) for c in row] for row in adj]
        assert strong_components(succ) == strong_components([list(x) for x in succ])


def test_edge_cases():
    assert maximum_matching([], 3) == []
    assert maximum_matching([[], [0]], 1) == [-1, 0]
    assert maximum_matching([[0], [0]], 1) in ([0, -1], [-1, 0])
    # a long chain of augmentations (no recursion limit)
    n = 3000
    adj = [[r, r + 1] if r + 1 < n else [r] for r in range(n)]
    adj = adj[::-1]
    match = maximum_matching(adj, n)
    assert -1 not in match
    # a path 0 -> 1 -> ... -> n-1 (v uses v+1): every vertex after the one it reaches
    assert strong_components([[v + 1] for v in range(n - 1)] + [[]]) == [[n - 1 - k] for k in range(n)]
    # a cycle through every vertex: one block
    assert strong_components([[(v + 1) % n] for v in range(n)]) == [list(range(n))]


def _models():
    """Every stage model of every spec. Built at collection, in every xdist worker: without the
    page-only work (``page=False``, as ``balpipe check``: the partial balancing's Pareto fronts,
    27 s of the 33 s), which changes no stage's model."""
    for path in sorted(glob.glob("specs/*.yaml")):
        spec = load(path).spec
        for stage in registry.balance(spec, page=False).stages:
            yield f"{path}:{stage.name}", stage.model


@pytest.mark.parametrize("name,model", list(_models()))
def test_decomposition_of_every_spec_model_matches_scipy(name, model):
    """The blocks (as sets of rows and columns) equal scipy's fine decomposition; a redundantly
    actuated (non-square) model has none; every block's entries are structurally non-singular
    and the order is block lower-triangular."""
    vz = vectorise(compile_model(model))
    dec = _decompose(vz)
    m, n = vz.m, vz.ncol - 3
    free = vz.structural & (vz.cols >= 3)
    R, C = vz.rows[free], vz.cols[free] - 3
    if m != n:
        assert dec is None
        return
    P = csr_matrix((np.ones(len(R)), (R, C)), shape=(m, n))
    if structural_rank(P) < n:
        assert dec is None
        return
    assert dec is not None
    match = maximum_bipartite_matching(P, perm_type="column")
    row_of_col = np.empty(n, dtype=int)
    row_of_col[match] = np.arange(m)
    nblk, label = connected_components(csr_matrix((np.ones(len(R)), (R, row_of_col[C])), shape=(m, m)),
                                       directed=True, connection="strong")
    ref = sorted((tuple(np.flatnonzero(label == b).tolist()), tuple(sorted(match[label == b].tolist())))
                 for b in range(nblk))
    assert sorted((tuple(r), tuple(c)) for r, c in dec.blocks) == ref
    col_block = {c: k for k, (_, cols) in enumerate(dec.blocks) for c in cols}
    for k, (rows, cols) in enumerate(dec.blocks):
        assert cols == sorted(cols)
        for r, c in zip(R.tolist(), C.tolist()):
            if r in rows:
                assert col_block[c] <= k


def test_structurally_singular_pattern_gives_none():
    """A square model whose pattern has no perfect matching: the decomposition refuses it (the
    dense path then reports the problem)."""
    from balpipe.model import FRAME, Body, Driver, Model, Revolute
    from balpipe.motion import PROFILES, PointToPoint

    b1 = Body("a", 1.0, (0.5, 0.0), 0.1, points={"p": (0.0, 0.0), "d": (1.0, 0.0)})
    b2 = Body("b", 1.0, (0.5, 0.0), 0.1, points={"p": (0.0, 0.0), "d": (1.0, 0.0)})
    law = PointToPoint(0.0, 1.0, 1.0, PROFILES["quintic"])
    # both drivers on body a's angle, none on b's: 6 rows, 6 coordinates, b's angle in no row
    model = Model("singular", (b1, b2),
                  (Revolute("O", FRAME, "a", (0.0, 0.0), (0.0, 0.0)), Revolute("A", FRAME, "b", (2.0, 0.0), (0.0, 0.0))),
                  (Driver("d1", ("joint", "O"), law), Driver("d2", ("angle", "a"), law)),
                  {"a": (0.0, 0.0, 0.0), "b": (2.0, 0.0, 0.0)})
    vz = vectorise(compile_model(model))
    assert vz.m == vz.ncol - 3
    assert _decompose(vz) is None
