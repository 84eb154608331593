"""A small named registry (benchopt-style) shared by every layer, and the scene catalogue.

It lives in ``scenes`` because that is the bottom layer: formulations, solvers and estimators
import it downwards.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

from scenes.base import SceneError

BUILT_IN = "built-in"
_ORIGINS = [BUILT_IN]  # where registrations come from now (a stack: files, plugins)
REGISTRIES: list[Registry] = []  # every registry, for listing and for undoing a failed plugin


@contextmanager
def registering_as(origin: str) -> Iterator[None]:
    """Record ``origin`` (a scene file, a plugin) for every registration inside the block."""
    _ORIGINS.append(origin)
    try:
        yield
    finally:
        _ORIGINS.pop()


def unregister_origin(origin: str) -> None:
    """Undo every registration of ``origin`` (a plugin that failed half-way)."""
    for registry in REGISTRIES:
        for name in [n for n in registry.names() if registry.origin(n) == origin]:
            registry.unregister(name)


def broken_units() -> list[tuple[str, Broken]]:
    """Every unit left out because it failed to load or build: (kind, Broken)."""
    return [(registry.kind, broken) for registry in REGISTRIES for broken in registry.broken()]


@dataclass(frozen=True)
class Entry:
    """One registration: the object, its one line of description, where it came from, the
    optional ``applies(**context)`` check and what is known of it without building it
    (``tags``, ``dim``: None when the registration does not say; ``meta``: what a kind of
    unit declares besides, e.g. whether an estimator is guaranteed)."""

    item: Any
    description: str
    origin: str
    applies: Callable[..., str | None] | None = None
    tags: tuple[str, ...] = ()
    dim: int | None = None
    meta: MappingProxyType = field(default_factory=lambda: MappingProxyType({}))


@dataclass(frozen=True)
class Broken:
    """A unit, file or plugin that failed to load or build: named once, left out."""

    name: str
    origin: str
    reason: str


class Registry:
    """Name -> ``Entry`` (the object, one line of description, its origin ``built-in``, a scene
    file or a plugin, and its metadata); unknown names list the valid ones, and broken ones
    say why they are broken."""

    def __init__(self, kind: str):
        self.kind = kind
        self._entries: dict[str, Entry] = {}
        self._broken: dict[str, Broken] = {}
        REGISTRIES.append(self)

    def register(self, name: str, description: str,
                 applies: Callable[..., str | None] | None = None, *,
                 tags: tuple[str, ...] = (), dim: int | None = None,
                 meta: dict | None = None) -> Callable[[Any], Any]:
        """``applies(**context)`` (optional) returns why ``name`` cannot be combined with the
        context (e.g. scene=..., formulation=...), or None when it can; ``tags``, ``dim`` and
        ``meta`` are what a command may know of the unit without building it (kept with the
        entry, so unregistering it forgets them too)."""
        def decorate(item: Any) -> Any:
            if name in self._entries:
                raise ValueError(f"{self.kind} {name!r} is already registered")
            self._entries[name] = Entry(item, description, _ORIGINS[-1], applies,
                                        tuple(tags), dim, MappingProxyType(dict(meta or {})))
            self._broken.pop(name, None)
            return item

        return decorate

    def unregister(self, name: str) -> None:
        self._entries.pop(name, None)
        self._broken.pop(name, None)

    def mark_broken(self, name: str, reason: str, origin: str | None = None) -> None:
        """Leave ``name`` out (unregistered if it was) and remember why, for ``list`` and for
        the error of a command that asks for it."""
        entry = self._entries.pop(name, None)
        where = origin or (entry.origin if entry is not None else _ORIGINS[-1])
        self._broken[name] = Broken(name, where, reason)

    def broken(self) -> list[Broken]:
        return [self._broken[name] for name in sorted(self._broken)]

    def entry(self, name: str) -> Entry:
        self.get(name)
        return self._entries[name]

    def origin(self, name: str) -> str:
        """Where ``name`` was registered: ``built-in``, ``file PATH`` or ``plugin DIST``."""
        return self.entry(name).origin

    def why_not(self, name: str, **context) -> str | None:
        """The reason ``name`` does not apply to ``context``, or None."""
        check = self.entry(name).applies
        return check(**context) if check is not None else None

    def names(self) -> list[str]:
        return sorted(self._entries)

    def meta(self, name: str, key: str, default=None):
        """What ``name``'s registration declared under ``key`` (``default`` if nothing)."""
        return self.entry(name).meta.get(key, default)

    def items(self) -> list[tuple[str, Any]]:
        return [(name, self._entries[name].item) for name in self.names()]

    def descriptions(self) -> dict[str, str]:
        return {name: self._entries[name].description for name in self.names()}

    def get(self, name: str) -> Any:
        if name in self._broken:
            broken = self._broken[name]
            raise KeyError(f"{self.kind} {name!r} is broken ({broken.origin}): {broken.reason}")
        if name not in self._entries:
            raise KeyError(f"unknown {self.kind} {name!r}; valid {self.kind}s: "
                           f"{', '.join(self.names())}")
        return self._entries[name].item


SCENES = Registry("scene")
register_scene = SCENES.register
scene_names = SCENES.names
scene_descriptions = SCENES.descriptions


def get_scene(name: str, **parameters):
    """Build the scene ``name`` from its factory with the given parameters; a scene whose
    registration declares its dimension or tags must build with them (SceneError)."""
    scene = SCENES.get(name)(**parameters)
    entry = SCENES.entry(name)
    declared = getattr(scene, "dim", entry.dim)
    if entry.dim is not None and declared != entry.dim:
        raise SceneError(f"scene {name!r} is registered with dim={entry.dim} but builds a "
                         f"{declared}D mesh")
    missing = set(entry.tags) - set(getattr(scene, "tags", entry.tags))
    if missing:
        raise SceneError(f"scene {name!r} is registered with tags {sorted(entry.tags)} but "
                         f"builds one without {sorted(missing)}")
    return scene


def scene_tags(name: str) -> tuple[str, ...]:
    """The tags a scene's registration declares (nothing is built)."""
    return SCENES.entry(name).tags


def scene_dim(name: str) -> int | None:
    """The dimension a scene's registration declares, None if it does not (nothing built)."""
    return SCENES.entry(name).dim
