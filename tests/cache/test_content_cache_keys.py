"""The content caches' keys (balpipe.cache.content.feed): the bytes fed for every kind of input
are those of the format's first implementation, kept below as the reference (one isinstance
chain per value), on the specs' own models, stages and laws and on hand-made values of every
kind; a key that changed would make every existing cache entry unreachable."""

from __future__ import annotations

import collections
import dataclasses
import enum
import hashlib
import struct
import types
from pathlib import Path

import numpy as np
import pytest

from balpipe.cache import content as content_cache
from balpipe import loader, registry
from balpipe.cache.content import MEMO, Unhashable, callable_name

SPECS = sorted((Path(__file__).resolve().parents[2] / "specs").glob("*.yaml"))


def reference_feed(h, x) -> None:
    """The format as first written (balpipe 2026-12-04, f07f1c7), an isinstance chain a value."""
    if x is None:
        h.update(b"N")
    elif x is True or x is False:
        h.update(b"T" if x else b"F")
    elif isinstance(x, np.ndarray) or isinstance(x, np.generic):
        a = np.asarray(x)
        if a.dtype.hasobject:
            raise Unhashable("object array")
        data = np.ascontiguousarray(a).tobytes()
        h.update(b"A" + a.dtype.str.encode() + repr(a.shape).encode() + struct.pack("<Q", len(data)))
        h.update(data)
    elif isinstance(x, enum.Enum):
        h.update(b"E" + type(x).__qualname__.encode() + b"." + x.name.encode() + b"\0")
    elif isinstance(x, int):
        h.update(b"I" + str(int(x)).encode() + b"\0")
    elif isinstance(x, float):
        h.update(b"R" + float(x).hex().encode() + b"\0")
    elif isinstance(x, str):
        b = x.encode("utf-8", "surrogatepass")
        h.update(b"S" + struct.pack("<Q", len(b)) + b)
    elif isinstance(x, bytes):
        h.update(b"B" + struct.pack("<Q", len(x)) + x)
    elif isinstance(x, (list, tuple)):
        h.update((b"L" if isinstance(x, list) else b"U") + struct.pack("<Q", len(x)))
        for v in x:
            reference_feed(h, v)
    elif isinstance(x, dict):
        h.update(b"M" + struct.pack("<Q", len(x)))
        for k, v in x.items():
            reference_feed(h, k)
            reference_feed(h, v)
    elif isinstance(x, (set, frozenset)):
        parts = sorted(hashlib.sha256(reference_digest(v)).digest() for v in x)
        h.update(b"Z" + struct.pack("<Q", len(parts)) + b"".join(parts))
    elif dataclasses.is_dataclass(x) and not isinstance(x, type):
        cls = type(x)
        h.update(b"C" + f"{cls.__module__}.{cls.__qualname__}".encode() + b"\0")
        fields = [f for f in dataclasses.fields(x) if not f.metadata.get(MEMO)]
        h.update(struct.pack("<Q", len(fields)))
        for f in fields:
            h.update(f.name.encode() + b"=")
            reference_feed(h, getattr(x, f.name))
    elif isinstance(x, types.FunctionType):
        h.update(b"f" + callable_name(x, closures=True).encode() + b"\0")
        reference_feed(h, x.__defaults__)
        reference_feed(h, x.__kwdefaults__)
        reference_feed(h, tuple(c.cell_contents for c in (x.__closure__ or ())))
    elif hasattr(type(x), "model_fields") and hasattr(x, "model_dump_json"):
        cls = type(x)
        h.update(b"P" + f"{cls.__module__}.{cls.__qualname__}".encode() + b"\0")
        reference_feed(h, x.model_dump_json())
    else:
        raise Unhashable(type(x).__qualname__)


def reference_digest(x) -> bytes:
    h = hashlib.sha256()
    reference_feed(h, x)
    return h.digest()


class Colour(enum.Enum):
    RED = 1


class Level(enum.IntEnum):
    HIGH = 3


class Flags(int):
    pass


Pair = collections.namedtuple("Pair", "a b")


@dataclasses.dataclass
class Memo:
    value: float
    seen: dict = dataclasses.field(default_factory=dict, metadata={MEMO: True})


@dataclasses.dataclass
class Child(Memo):
    extra: tuple = ()


def _profile(s):
    return s * s


def _closure(k):
    def inner(s, scale=2.0, *, shift=0.5):
        return k * s * scale + shift
    return inner


VALUES = [None, True, False, 0, -7, 2**80, 1.0, -0.0, float("inf"), float("nan"), 1e-300, "", "é\u2603",
          b"", b"\x00\xff", [], (), [1, 1.0, "1", (1,)], {"b": 1, "a": [2.5]}, {3, "x", (1, 2)}, frozenset({0.5}),
          np.arange(6.0).reshape(2, 3), np.arange(6.0).reshape(2, 3).T, np.float64(2.5), np.int32(4), np.bool_(True),
          np.zeros((0, 3)), Colour.RED, Level.HIGH, Flags(5), Pair(1.5, "q"), Memo(2.0, {"kept": 1}),
          Child(1.0, {}, (np.ones(2), None)), _profile, _closure(3.0)]


@pytest.mark.parametrize("value", VALUES, ids=[f"{type(v).__name__}-{i}" for i, v in enumerate(VALUES)])
def test_every_kind_is_fed_as_the_reference(value):
    assert content_cache.digest_of(value) == reference_digest(value)


def test_the_kinds_do_not_collide():
    digests = [content_cache.digest_of(v) for v in (1, 1.0, "1", [1], (1,), True, np.int64(1), Colour.RED, b"1")]
    assert len(set(digests)) == len(digests)


@pytest.mark.parametrize("value", [lambda s: s, object(), np.array([object()]), {1: object()}])
def test_what_cannot_be_fed_is_refused(value):
    with pytest.raises(Unhashable):
        content_cache.digest_of(value)


@pytest.mark.parametrize("path", SPECS, ids=[p.stem for p in SPECS])
def test_spec_models_are_fed_as_the_reference(path):
    """A spec's pydantic model, its mechanism's Model (bodies, joints, drivers with their laws)."""
    spec = loader.load(path).spec
    model = registry.unbalanced_model(spec)
    for value in (spec, model, (model, spec.analysis)):
        assert content_cache.digest_of(value) == reference_digest(value)
