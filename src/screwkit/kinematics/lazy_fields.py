"""Per-sample fields computed on first access (issue 30: writing every optional field of a
Motion cost more than the solve that needs them).

A closed form that returns optional fields (the CSSP's ball-joint rotations, their rates and
rotation vectors, Rahman's joint angles) hands them over as

* :class:`LazyTable` — a ``dict`` of (N,) arrays by name, in a fixed key order, some of whose
  entries are computed on the first read of one of them (or of the whole table: iteration,
  ``keys``/``items``/``values``, ``len`` is known without it, ``in`` too); a write loads it
  first. Once loaded it is an ordinary dict with the same keys in the same order and the same
  values as the eager table it stands for;
* :class:`LazyConfiguration` — a :class:`~screwkit.kinematics.tracker.loop.Configuration` whose
  ``spherical`` rotations are computed on first access.

Both pickle (and deep-copy) as their plain, loaded counterparts. The values are computed by a
:class:`LazyFields` shared by a mode's tables, so one pass fills every table of the group.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator, Mapping
from typing import Any

import numpy as np
from numpy.typing import NDArray

from screwkit.errors import InputError
from screwkit.kinematics.tracker.loop import Configuration

Array = NDArray[np.float64]


class LazyFields:
    """A group of arrays by name, computed once by ``compute()`` on the first :meth:`get`."""

    def __init__(self, compute: Callable[[], dict[str, Any]]) -> None:
        self._compute: Callable[[], dict[str, Any]] | None = compute
        self._values: dict[str, Any] | None = None

    @property
    def computed(self) -> bool:
        return self._values is not None

    def get(self) -> dict[str, Any]:
        if self._values is None:
            assert self._compute is not None
            self._values = self._compute()
            self._compute = None  # let what it closed over go
        return self._values


class LazyTable(dict[str, Array]):
    """A table of (N,) arrays by name whose ``lazy`` entries come from ``source()`` (a mapping
    holding at least those names) on first need; ``order`` is every key, in the table's order
    (module docstring)."""

    def __init__(self, order: Iterable[str], eager: Mapping[str, Array],
                 lazy: Iterable[str], source: Callable[[], Mapping[str, Array]]) -> None:
        order = tuple(order)
        lazy = frozenset(lazy)
        if set(order) != set(eager) | lazy or lazy & set(eager):
            raise InputError("LazyTable: order must list the eager and the lazy names, each once")
        super().__init__((k, eager[k]) for k in order if k in eager)
        self._order = order
        self._lazy = lazy
        self._source: Callable[[], Mapping[str, Array]] | None = source

    # --- loading --------------------------------------------------------------------------
    @property
    def loaded(self) -> bool:
        return self._source is None

    def _load(self) -> None:
        if self._source is None:
            return
        source, self._source = self._source, None
        values = source()
        eager = dict(dict.items(self))
        dict.clear(self)
        for k in self._order:
            dict.__setitem__(self, k, eager[k] if k in eager else values[k])
        self._lazy = frozenset()

    def mapped(self, fn: Callable[[Array], Array]) -> LazyTable:
        """A table of ``fn`` of each entry: the eager entries now, the lazy ones when the new
        table is first read (this table is loaded then)."""
        if self._source is None:
            eager = {k: fn(v) for k, v in dict.items(self)}
            return LazyTable(self._order, eager, (), dict)
        lazy = self._lazy  # the names this table has still to compute
        return LazyTable(self._order, {k: fn(v) for k, v in dict.items(self)}, lazy,
                         lambda: {k: fn(self[k]) for k in lazy})

    def derived(self, order: Iterable[str], extra: Mapping[str, Array],
                transforms: Mapping[str, Callable[[Array], Array]] | None = None) -> LazyTable:
        """A table with the keys ``order``, each a key of this table or of ``extra`` (eager
        entries, first in the new order as given there); this table's entries as they are,
        or through ``transforms[name]``: its lazy entries stay lazy (this table is loaded
        when the new one is first read)."""
        transforms = transforms or {}
        order = tuple(order)
        mine = [k for k in order if k not in extra]
        lazy = [k for k in mine if self._source is not None and k in self._lazy]
        eager = dict(extra)
        for k in mine:
            if k not in lazy:
                v = dict.__getitem__(self, k)
                eager[k] = transforms[k](v) if k in transforms else v

        def source() -> dict[str, Array]:
            return {k: transforms[k](self[k]) if k in transforms else self[k] for k in lazy}

        return LazyTable(order, eager, lazy, source)

    # --- reads that need one entry --------------------------------------------------------
    def __getitem__(self, key: str) -> Array:
        if self._source is not None and key in self._lazy:
            self._load()
        return dict.__getitem__(self, key)

    def get(self, key: str, default: Any = None) -> Any:  # type: ignore[override]
        if self._source is not None and key in self._lazy:
            self._load()
        return dict.get(self, key, default)

    def __contains__(self, key: object) -> bool:
        return dict.__contains__(self, key) or key in self._lazy

    def __len__(self) -> int:
        return len(self._order) if self._source is not None else dict.__len__(self)

    # --- reads of the whole table: load first ---------------------------------------------
    def __iter__(self) -> Iterator[str]:
        self._load()
        return dict.__iter__(self)

    def __reversed__(self) -> Iterator[str]:
        self._load()
        return dict.__reversed__(self)

    def keys(self) -> Any:
        self._load()
        return dict.keys(self)

    def values(self) -> Any:
        self._load()
        return dict.values(self)

    def items(self) -> Any:
        self._load()
        return dict.items(self)

    def copy(self) -> dict[str, Array]:
        self._load()
        return dict(dict.items(self))

    def __eq__(self, other: object) -> bool:
        self._load()
        if isinstance(other, LazyTable):
            other._load()
        return dict.__eq__(self, other)

    def __ne__(self, other: object) -> bool:
        return not self == other

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        self._load()
        return dict.__repr__(self)

    def __or__(self, other: Any) -> Any:
        self._load()
        return dict.__or__(self, other)

    def __ror__(self, other: Any) -> Any:
        self._load()
        return dict.__ror__(self, other)

    def __reduce__(self) -> Any:
        self._load()
        return (dict, (dict(dict.items(self)),))

    # --- writes: load first ---------------------------------------------------------------
    def __setitem__(self, key: str, value: Array) -> None:
        self._load()
        dict.__setitem__(self, key, value)

    def __delitem__(self, key: str) -> None:
        self._load()
        dict.__delitem__(self, key)

    def __ior__(self, other: Any) -> Any:
        self._load()
        return dict.__ior__(self, other)

    def pop(self, *args: Any) -> Any:
        self._load()
        return dict.pop(self, *args)

    def popitem(self) -> tuple[str, Array]:
        self._load()
        return dict.popitem(self)

    def setdefault(self, key: str, default: Any = None) -> Any:
        self._load()
        return dict.setdefault(self, key, default)

    def update(self, *args: Any, **kwargs: Any) -> None:
        self._load()
        dict.update(self, *args, **kwargs)

    def clear(self) -> None:
        self._load()
        dict.clear(self)


def mapped_table(table: dict[str, Array], fn: Callable[[Array], Array]) -> dict[str, Array]:
    """``{k: fn(v)}`` of a table, keeping a :class:`LazyTable`'s lazy entries lazy."""
    if isinstance(table, LazyTable):
        return table.mapped(fn)
    return {k: fn(v) for k, v in table.items()}


def table_keys(table: dict[str, Array]) -> tuple[str, ...]:
    """A table's keys in order, without loading a :class:`LazyTable`."""
    if isinstance(table, LazyTable) and not table.loaded:
        return table._order
    return tuple(dict.keys(table))


def derived_table(table: dict[str, Array], order: Iterable[str], extra: Mapping[str, Array],
                  transforms: Mapping[str, Callable[[Array], Array]] | None = None
                  ) -> dict[str, Array]:
    """:meth:`LazyTable.derived` of any table (a plain dict gives a plain dict)."""
    if isinstance(table, LazyTable):
        return table.derived(order, extra, transforms)
    transforms = transforms or {}
    return {k: extra[k] if k in extra else
            (transforms[k](table[k]) if k in transforms else table[k]) for k in order}


class LazyConfiguration(Configuration):
    """A :class:`Configuration` whose ``spherical`` (N, n_S, 3, 3) comes from ``spherical()``
    on first access."""

    def __init__(self, scalars: Array, spherical: Callable[[], Array]) -> None:
        object.__setattr__(self, "scalars", scalars)
        object.__setattr__(self, "_spherical_source", spherical)

    def __getattr__(self, name: str) -> Any:
        if name == "spherical":
            value = self.__dict__["_spherical_source"]()
            object.__setattr__(self, "spherical", value)
            return value
        raise AttributeError(name)

    def __reduce__(self) -> Any:
        return (Configuration, (self.scalars, self.spherical))
