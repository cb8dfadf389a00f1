"""Which specs describe the same mechanism: a short key of the unbalanced model's linkage.

Two specs share a key exactly when their unbalanced models have the same bodies (name, mass,
centre of mass, centroidal inertia, named points, attachments) and the same joints (kind, bodies,
points, axes), every number compared to 12 significant digits (and below 1e-15 as 0: the
round-off of a point placed by trigonometry, cos 90 deg = 6.1e-17, is not a different linkage). The drivers, the motion, the loads
and the balancing method are left out: they are what a comparison of methods on one mechanism
varies. The site index groups its "Methods compared" tables by this key.
"""

from __future__ import annotations

import dataclasses
import hashlib
from typing import Any

from ..model import Model


def _canonical(x: Any) -> Any:
    """Numbers as 12-significant-digit text, containers recursively, dataclasses as their kind
    and fields (the ``sources`` of a model, which name spec lines, are not part of it)."""
    if dataclasses.is_dataclass(x) and not isinstance(x, type):
        return [type(x).__name__] + [[f.name, _canonical(getattr(x, f.name))]
                                     for f in dataclasses.fields(x) if f.compare]
    if isinstance(x, dict):
        return [[str(k), _canonical(v)] for k, v in sorted(x.items(), key=lambda kv: str(kv[0]))]
    if isinstance(x, (list, tuple)):
        return [_canonical(v) for v in x]
    if isinstance(x, bool) or x is None or isinstance(x, str):
        return x
    try:
        v = float(x)
        return "0" if abs(v) < 1e-15 else f"{v:.12g}"
    except (TypeError, ValueError):
        return repr(x)


def mechanism_key(model: Model) -> str:
    """12 hexadecimal digits naming the linkage of ``model`` (its bodies and joints)."""
    text = repr([_canonical(model.bodies), _canonical(model.joints)])
    return hashlib.sha256(text.encode("utf-8")).hexdigest()[:12]


def describe(bodies: list[str]) -> str:
    """'crank, coupler and rocker' from the moving bodies' names."""
    if len(bodies) <= 1:
        return "".join(bodies)
    return ", ".join(bodies[:-1]) + " and " + bodies[-1]
