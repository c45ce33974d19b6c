"""Validated data: build frozen dataclasses from TOML tables with clear errors.

Every scene table maps to a frozen dataclass.  :func:`build` walks the
dataclass fields, so

* an unknown key is an error naming the key (``parts.0.radus: unknown key``, the key as ``--set`` spells it),
* a missing value is an error naming the key,
* a wrong type is an error naming the key, the expected and the given type,
* each dataclass may define ``check(self, path)`` for range checks, raising
  :class:`SceneError` through :func:`fail`.

Tagged unions (a material's ``model``, a part's ``shape``, an initial
condition's ``kind``) are resolved through a :class:`Registry`, never through
``if`` chains.
"""
from __future__ import annotations

import dataclasses
import math
import types
import typing


class SceneError(ValueError):
    """A scene is invalid.  ``str(err)`` is one line: ``<key path>: <reason>``."""

    def __init__(self, path: str, reason: str):
        self.path = path
        self.reason = reason
        super().__init__(f"{path}: {reason}" if path else reason)


def fail(path: str, reason: str) -> typing.NoReturn:
    raise SceneError(path, reason)


def join(path: str, key) -> str:
    """A key's path as ``--set`` spells it: ``parts.1.dx`` (an array's entries by
    number, as tables' keys), so that an error's key can be pasted back."""
    return f"{path}.{key}" if path else str(key)


class Registry:
    """Name -> class table for one family of scene objects (materials, shapes, …)."""

    def __init__(self, what: str, tag: str):
        self.what = what
        self.tag = tag
        self._table: dict[str, type] = {}

    def register(self, name: str):
        def deco(cls):
            if name in self._table:
                raise RuntimeError(f"{self.what} {name!r} registered twice")
            self._table[name] = cls
            cls.registry_name = name
            return cls
        return deco

    def names(self) -> list[str]:
        return sorted(self._table)

    def get(self, name: str) -> type:
        return self._table[name]

    def build(self, table, path: str):
        if not isinstance(table, dict):
            fail(path, f"expected a table, got {_tname(table)}")
        if self.tag not in table:
            fail(join(path, self.tag), f"missing value (one of: {', '.join(self.names())})")
        name = table[self.tag]
        if name not in self._table:
            fail(join(path, self.tag),
                 f"unknown {self.what} {name!r} (known: {', '.join(self.names())})")
        rest = {k: v for k, v in table.items() if k != self.tag}
        return build(self._table[name], rest, path)


def _tname(v) -> str:
    return {dict: "table", list: "array", str: "string", bool: "boolean",
            int: "integer", float: "float"}.get(type(v), type(v).__name__)


#: integers a scene may hold: int64's range (HDF5 attributes, NumPy seeds)
INT_LIMIT = 2 ** 63


def _coerce(tp, value, path):
    """Check/convert one TOML value against a type annotation."""
    origin = typing.get_origin(tp)
    args = typing.get_args(tp)
    if tp is typing.Any:
        return value
    if origin in (typing.Union, types.UnionType):
        if value is None and type(None) in args:
            return None
        options = [a for a in args if a is not type(None)]
        # an optional table (X | None, X a dataclass) is switched off by ``false``,
        # TOML having no null: e.g. ``--set materials.explosive.contact=false``
        if (value is False and type(None) in args
                and all(dataclasses.is_dataclass(a) for a in options)):
            return None
        if len(options) == 1:               # X | None: X's own error, with its own key path
            return _coerce(options[0], value, path)
        errors = []
        for a in args:
            if a is type(None):
                continue
            try:
                return _coerce(a, value, path)
            except SceneError as e:
                errors.append(e.reason)
        fail(path, errors[0] if len(errors) == 1 else "; or ".join(errors))
    if origin is typing.Literal:
        if value not in args:
            fail(path, f"must be one of {', '.join(repr(a) for a in args)} (got {value!r})")
        return value
    if tp is float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            fail(path, f"expected a number, got {_tname(value)} {value!r}")
        if not math.isfinite(value):
            fail(path, f"must be a finite number (got {value!r})")
        return float(value)
    if tp is int:
        if isinstance(value, bool) or not isinstance(value, int):
            fail(path, f"expected an integer, got {_tname(value)} {value!r}")
        if not -INT_LIMIT <= value < INT_LIMIT:        # run files and seeds hold int64
            fail(path, f"must be below 2^63 in size (got {value})")
        return value
    if tp is bool:
        if not isinstance(value, bool):
            fail(path, f"expected true or false, got {_tname(value)} {value!r}")
        return value
    if tp is str:
        if not isinstance(value, str):
            fail(path, f"expected a string, got {_tname(value)} {value!r}")
        return value
    if origin is tuple:
        if not isinstance(value, list):
            fail(path, f"expected an array, got {_tname(value)} {value!r}")
        if len(args) == 2 and args[1] is Ellipsis:
            return tuple(_coerce(args[0], v, join(path, i)) for i, v in enumerate(value))
        if len(value) != len(args):
            fail(path, f"expected an array of {len(args)} values, got {len(value)}")
        return tuple(_coerce(a, v, join(path, i)) for i, (a, v) in enumerate(zip(args, value)))
    if origin is dict:
        if not isinstance(value, dict):
            fail(path, f"expected a table, got {_tname(value)}")
        return {k: _coerce(args[1], v, join(path, k)) for k, v in value.items()}
    if isinstance(tp, Registry):
        return tp.build(value, path)
    if dataclasses.is_dataclass(tp):
        return build(tp, value, path)
    raise TypeError(f"schema: unsupported annotation {tp!r} at {path}")


def build(cls, table, path: str = ""):
    """Build dataclass ``cls`` from a TOML table, validating every key."""
    if not isinstance(table, dict):
        fail(path, f"expected a table, got {_tname(table)}")
    hints = typing.get_type_hints(cls, include_extras=True)
    fields = {f.name: f for f in dataclasses.fields(cls) if f.init}
    for key in table:
        if key not in fields:
            fail(join(path, key), f"unknown key (allowed: {', '.join(sorted(fields))})")
    kwargs = {}
    for name, f in fields.items():
        tp = hints[name]
        meta_tp = f.metadata.get("registry")
        if name in table:
            if meta_tp is not None:
                kwargs[name] = _build_tagged(meta_tp, table[name], join(path, name))
            else:
                kwargs[name] = _coerce(tp, table[name], join(path, name))
        elif f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING:
            fail(join(path, name), "missing value")
    obj = cls(**kwargs)
    check = getattr(obj, "check", None)
    if check is not None:
        check(path)
    return obj


def _build_tagged(spec, value, path):
    registry, container = spec
    if container is None:
        return registry.build(value, path)
    if container is list:
        if not isinstance(value, list):
            fail(path, f"expected an array of tables, got {_tname(value)}")
        return tuple(registry.build(v, join(path, i)) for i, v in enumerate(value))
    if not isinstance(value, dict):
        fail(path, f"expected a table, got {_tname(value)}")
    return {k: registry.build(v, join(path, k)) for k, v in value.items()}


def tagged(registry: Registry, container=None, **kw):
    """A dataclass field resolved through ``registry``: one value, or a
    ``list`` (array of tables) or ``dict`` (table of tables) of them."""
    return dataclasses.field(metadata={"registry": (registry, container)}, **kw)


def positive(obj, path: str, *names: str) -> None:
    for n in names:
        v = getattr(obj, n)
        if not v > 0:
            fail(join(path, n), f"must be > 0 (got {v!r})")


def non_negative(obj, path: str, *names: str) -> None:
    for n in names:
        v = getattr(obj, n)
        if not v >= 0:
            fail(join(path, n), f"must be >= 0 (got {v!r})")


def ordered_box(obj, path: str, strict: bool) -> None:
    """``obj.hi`` above (``strict``) or not below ``obj.lo`` on every axis."""
    for a in range(3):
        lo, hi = obj.lo[a], obj.hi[a]
        if (hi <= lo) if strict else (hi < lo):
            rel = "exceed" if strict else "not be below"
            fail(join(path, "hi"), f"must {rel} lo on axis {'xyz'[a]} ({hi} vs {lo})")
