"""Names on a mechanism drawing that do not overlap, and the numbers of its gears.

:func:`place` is a small deterministic label placer: every label tries candidate positions on
rings of growing radius around its anchor (8 directions on the first rings, 16 further out) and
takes the first one whose box (shifted into the drawing where it sticks out) overlaps no label
placed before it and crosses no link, disc or joint marker; when every candidate of the rings
touches a link, the first one free of labels is used; a label that had to leave the first ring
(or was shifted) is drawn with a leader line. Same input, same output: no randomness, no dependence on dictionary or set order.

:func:`gear_numbers` numbers the gears and counter-rotating discs the way the papers do (paper
004: gears 1', 2', 5, 6, 7; paper 000: counter-rotations 1-4; paper 002: gears 1', 2', 3): the
number a part's name carries (``gear 5``, ``gear5``, ``gear1p`` = 1', ``cr1.2`` = 1 on leg 2),
else the next free number in the order the models list their parts.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

from ..mechanics.planar import world_point
from ..model import Model

Box = tuple[float, float, float, float]  # x0, y0, x1, y1 (y up)
Segment = tuple[tuple[float, float], tuple[float, float]]

# first ring: beside the anchor; further rings: displaced, with a leader line
RINGS = (1.0, 2.6, 4.6, 7.0, 10.0, 14.0, 19.0)


@dataclass(frozen=True)
class Request:
    """A label to place: its text, the point it names and its box size (drawing units)."""

    text: str
    anchor: tuple[float, float]
    width: float
    height: float
    kind: str = "joint"  # pivot, joint, gear, counterweight, link
    clear: float = 0.0  # radius around the anchor to leave free (its own marker or disc)


@dataclass(frozen=True)
class Placed:
    request: Request
    box: Box
    displaced: bool  # drawn with a leader line from the anchor

    @property
    def centre(self) -> tuple[float, float]:
        return (0.5 * (self.box[0] + self.box[2]), 0.5 * (self.box[1] + self.box[3]))


def _directions(n: int) -> list[tuple[float, float]]:
    """n unit directions, starting east then north-east, anticlockwise (rounded: exact zeros)."""
    return [(round(math.cos(2 * math.pi * k / n), 12), round(math.sin(2 * math.pi * k / n), 12)) for k in range(n)]


def _candidate(anchor, w, h, d, r) -> Box:
    """The box whose edge nearest the anchor sits at distance ``r`` in direction ``d``."""
    cx = anchor[0] + d[0] * (r + 0.5 * w)
    cy = anchor[1] + d[1] * (r + 0.5 * h)
    return (cx - 0.5 * w, cy - 0.5 * h, cx + 0.5 * w, cy + 0.5 * h)


def overlaps(a: Box, b: Box) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


def segment_hits_box(seg: Segment, box: Box) -> bool:
    """Liang-Barsky: does the segment cross the (closed) box?"""
    (x0, y0), (x1, y1) = seg
    dx, dy = x1 - x0, y1 - y0
    t0, t1 = 0.0, 1.0
    for p, q in ((-dx, x0 - box[0]), (dx, box[2] - x0), (-dy, y0 - box[1]), (dy, box[3] - y0)):
        if p == 0:
            if q < 0:
                return False
        else:
            t = q / p
            if p < 0:
                t0 = max(t0, t)
            else:
                t1 = min(t1, t)
            if t0 > t1:
                return False
    return True


def _inside(box: Box, bounds: Box | None) -> bool:
    return bounds is None or (box[0] >= bounds[0] and box[1] >= bounds[1] and box[2] <= bounds[2] and box[3] <= bounds[3])


def _clamp(box: Box, bounds: Box | None) -> tuple[Box, bool]:
    """The box shifted into ``bounds`` where it sticks out (and whether it moved)."""
    if bounds is None or _inside(box, bounds):
        return box, False
    dx = max(0.0, bounds[0] - box[0]) - max(0.0, box[2] - bounds[2])
    dy = max(0.0, bounds[1] - box[1]) - max(0.0, box[3] - bounds[3])
    return (box[0] + dx, box[1] + dy, box[2] + dx, box[3] + dy), True


def place(requests: list[Request], segments: list[Segment] = (), blocks: list[Box] = (),
          bounds: Box | None = None, gap: float = 3.0) -> list[Placed]:
    """Place ``requests`` in order (earlier ones get the better spots). ``segments``: the links
    (drawing units); ``blocks``: boxes to keep clear (joint markers, discs; those holding the
    label's own anchor are its own, left by ``Request.clear``); ``bounds``: the
    drawing area. Labels never overlap each other; they avoid links and blocks where a candidate
    allows it, and leave ``bounds`` only when nothing inside is free of labels."""
    done: list[Placed] = []
    anchors = [(r.anchor[0] - gap, r.anchor[1] - gap, r.anchor[0] + gap, r.anchor[1] + gap) for r in requests]
    for idx, req in enumerate(requests):
        w, h = req.width, req.height
        step = max(h, gap)
        rings = [(k, req.clear + gap + (ring - 1.0) * step) for k, ring in enumerate(RINGS)]
        own = [b for b in blocks if b[0] <= req.anchor[0] <= b[2] and b[1] <= req.anchor[1] <= b[3]]
        fallback = None
        chosen = None
        for k, r in rings:
            for d in _directions(8 if k < 2 else 16):
                box, moved = _clamp(_candidate(req.anchor, w, h, d, r), bounds)
                if not _inside(box, bounds) or any(overlaps(box, p.box) for p in done):
                    continue
                clear = (not any(segment_hits_box(s, box) for s in segments)
                         and not any(overlaps(box, b) for b in blocks if b not in own)
                         and not any(overlaps(box, a) for j, a in enumerate(anchors) if j != idx))
                if clear:
                    chosen = (box, k > 0 or moved)
                    break
                if fallback is None:
                    fallback = (box, k > 0 or moved)
            if chosen:
                break
        if chosen is None:
            chosen = fallback
        if chosen is None:  # nothing inside the drawing is free of labels: go further out
            r = rings[-1][1]
            while chosen is None:
                r += step
                for d in _directions(16):
                    box = _candidate(req.anchor, w, h, d, r)
                    if not any(overlaps(box, p.box) for p in done):
                        chosen = (box, True)
                        break
        done.append(Placed(req, chosen[0], chosen[1]))
    return done


_NUMBER = re.compile(r"(\d+)('*|p+)(?:\.\d+)?$")


def number_in_name(name: str) -> str | None:
    """The gear number a part's name carries: 'gear 5' -> 5, "gear 1'" -> 1', 'gear1p' -> 1'
    (p for prime, as the specs spell it), 'cr1.2' -> 1 (counter-rotation 1 of leg 2), '7' -> 7;
    None where the name carries no number ('disc_crank')."""
    m = _NUMBER.search(name.strip())
    if m is None:
        return None
    primes = m.group(2)
    return m.group(1) + "'" * len(primes)


def gear_parts(model: Model) -> list[str]:
    """The names of a model's gears and counter-rotating discs, in the order the model lists
    them: bodies drawn as discs, then (per body) the gears carried as attachments."""
    out = []
    for b in model.bodies:
        if b.radius:
            out.append(b.name)
        for a in b.attachments:
            if a.radius and a.kind != "counterweight":
                out.append(a.name)
    return out


def gear_numbers(models: list[Model]) -> dict[str, str]:
    """Part name -> the number drawn on it, the same in every panel of a page: the number in
    the name, else the next number not taken, in the order the models list their gears."""
    names: list[str] = []
    for m in models:
        for n in gear_parts(m):
            if n not in names:
                names.append(n)
    out = {n: num for n in names if (num := number_in_name(n)) is not None}
    taken = {int(re.match(r"\d+", v).group()) for v in out.values()}
    nxt = 1
    for n in names:
        if n not in out:
            while nxt in taken:
                nxt += 1
            out[n] = str(nxt)
            taken.add(nxt)
    return out


def gear_key(numbers: dict[str, str]) -> str:
    """'1 = cr1.1, cr1.2, cr1.3; 2 = cr2' (numbers in natural order)."""
    by: dict[str, list[str]] = {}
    for name, num in numbers.items():
        by.setdefault(num, []).append(name)

    def order(num: str):
        return (int(re.match(r"\d+", num).group()), num)

    return "; ".join(f"{num} = {', '.join(by[num])}" for num in sorted(by, key=order))


def place_key(p, span: float) -> tuple[float, float]:
    """A place of a drawing (model coordinates rounded to 1 % of its ``span``): points at one
    place are named once."""
    return (round(float(p[0]) / span, 2), round(float(p[1]) / span, 2))


def drawing_span(model: Model, poses) -> float:
    """The size of a drawing of ``model`` over ``poses`` (instants x bodies x (x, y, angle)): the
    larger extent of the bodies' origins and the frame pivots (m)."""
    xy = np.asarray(poses, dtype=float)[:, :, :2].reshape(-1, 2)
    fp = np.array(list(model.frame_points.values()) or [[0.0, 0.0]], dtype=float)
    allp = np.vstack([xy, fp])
    return float(max(np.ptp(allp[:, 0]), np.ptp(allp[:, 1]), 1e-3))


def point_places(model: Model, pose_row, span: float) -> list[tuple[str, np.ndarray]]:
    """The places of the body points at one instant (the frame pivots' places left to the
    pivots; discs' axes to the discs' numbers), each with one name: of the points that coincide
    there, the first whose name no other body point of the model has (the platform's C1, not the
    piston's C of every leg)."""
    pivots = {place_key(p, span) for p in model.frame_points.values()}
    count = point_name_counts(model)
    chosen: dict[tuple[float, float], tuple[str, np.ndarray]] = {}
    for i, b in enumerate(model.bodies):
        if b.kind == "gear" and b.radius:
            continue
        pose = tuple(float(v) for v in pose_row[i])
        for name, p in b.points.items():
            g = world_point(pose, p)
            key = place_key(g, span)
            if key in pivots:
                continue
            if key not in chosen or (count[chosen[key][0]] > 1 and count[name] == 1):
                chosen[key] = (name, chosen[key][1] if key in chosen else g)
    return list(chosen.values())


def repeated_names(places: list[tuple[str, np.ndarray]]) -> set[str]:
    """The names of :func:`point_places` at more than one place (each 3-RPR leg's ``tip`` and
    ``B``: a body's own name for its point, repeated on every leg). They name no one point, and
    the drawings and the player leave them off (every named point is named once); the links'
    names tell those bodies apart."""
    seen: dict[str, int] = {}
    for name, _ in places:
        seen[name] = seen.get(name, 0) + 1
    return {n for n, k in seen.items() if k > 1}


def point_name_counts(model: Model) -> dict[str, int]:
    """How many bodies of ``model`` have a point of each name: where points coincide, the
    drawings and the player name the place by a name only one body has (the 3-RPR platform's
    C1, not the C of every leg's piston)."""
    count: dict[str, int] = {}
    for b in model.bodies:
        for name in b.points:
            count[name] = count.get(name, 0) + 1
    return count
