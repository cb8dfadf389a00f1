"""Which poses a mechanism drawing shows: one reference pose drawn solid, the extreme poses as ghosts.

The reference pose is the motion's first sample, t = 0, where the page's player starts
(:mod:`.player`: its time slider starts at 0).

The extreme poses are the instants where the mechanism is farthest from the reference pose:
the local maxima over time of its excursion

    e(t) = sqrt( mean_j |p_j(t) - p_j(0)|^2 ),

the root-mean-square distance of its named points p_j (joint centres, link ends; a body with no
named point counts by its frame's origin) from where they are at t = 0. The last sample counts
as a maximum when e still grows there. So a point-to-point motion shows its end pose (or the
overshoot of a law that passes it), a cycle the farthest excursion of its swing (a crank's
opposite dead centre), a motion that goes out and back twice both far poses. Maxima smaller
than ``NEGLIGIBLE`` of the largest (poses that would hide behind the solid one) and poses within
``NEGLIGIBLE`` of one already chosen are not drawn; at most ``MOST`` are, the largest first.
Pure functions of the sampled poses: the same motion always gives the same instants.
"""

from __future__ import annotations

import numpy as np

from ..model import Model

REFERENCE = 0  # the sample drawn solid: t = 0, the player's start
MOST = 2  # extreme poses drawn at most
NEGLIGIBLE = 0.05  # of the largest excursion


def point_tracks(model: Model, poses: np.ndarray) -> np.ndarray:
    """(N, P, 2) global positions over the N samples of every body's named points (its frame's
    origin for a body without one); ``poses`` (N, bodies, 3) as ``analysis.frame_pose``."""
    tracks = []
    for i, b in enumerate(model.bodies):
        x, y, th = poses[:, i, 0], poses[:, i, 1], poses[:, i, 2]
        c, s = np.cos(th), np.sin(th)
        for px, py in (list(b.points.values()) or [(0.0, 0.0)]):
            tracks.append(np.stack([x + c * px - s * py, y + s * px + c * py], axis=1))
    if not tracks:
        return np.zeros((len(poses), 0, 2))
    return np.stack(tracks, axis=1)


def excursion(model: Model, poses: np.ndarray, reference: int = REFERENCE) -> np.ndarray:
    """(N,) e(t): RMS distance (m) of the named points from their positions at sample ``reference``."""
    xy = point_tracks(model, poses)
    if xy.shape[1] == 0:
        return np.zeros(len(poses))
    d2 = np.sum((xy - xy[reference]) ** 2, axis=2)
    return np.sqrt(np.mean(d2, axis=1))


def _distance(xy: np.ndarray, a: int, b: int) -> float:
    return float(np.sqrt(np.mean(np.sum((xy[a] - xy[b]) ** 2, axis=1)))) if xy.shape[1] else 0.0


def extreme_instants(model: Model, poses: np.ndarray, reference: int = REFERENCE, most: int = MOST) -> list[int]:
    """The samples of the extreme poses (module docstring), in time order."""
    e = excursion(model, poses, reference)
    n = len(e)
    if n < 2 or not float(e.max()) > 0:
        return []
    top = float(e.max())
    peaks = [k for k in range(1, n)
             if e[k] >= e[k - 1] and (k == n - 1 or e[k] > e[k + 1]) and e[k] >= NEGLIGIBLE * top]
    peaks.sort(key=lambda k: (-float(e[k]), k))
    xy = point_tracks(model, poses)
    chosen: list[int] = []
    for k in peaks:
        if len(chosen) == most:
            break
        if all(_distance(xy, k, c) >= NEGLIGIBLE * top for c in chosen):
            chosen.append(k)
    return sorted(chosen)
