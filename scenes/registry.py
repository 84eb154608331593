"""A small named registry (benchopt-style) shared by every layer, and the scene catalogue.

It lives in ``scenes`` because that is the bottom layer: formulations, solvers and estimators
import it downwards.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

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


class Registry:
    """Name -> object with one line of description and its origin (``built-in``, a scene file,
    a plugin); unknown names list the valid ones."""

    def __init__(self, kind: str):
        self.kind = kind
        self._items: dict[str, tuple[Any, str]] = {}
        self._applies: dict[str, Callable[..., str | None]] = {}
        self._origins: dict[str, str] = {}
        REGISTRIES.append(self)

    def register(self, name: str, description: str,
                 applies: Callable[..., str | None] | None = None) -> Callable[[Any], Any]:
        """``applies(**context)`` (optional) returns why ``name`` cannot be combined with the
        context (e.g. scene=..., formulation=...), or None when it can."""
        def decorate(item: Any) -> Any:
            if name in self._items:
                raise ValueError(f"{self.kind} {name!r} is already registered")
            self._items[name] = (item, description)
            self._origins[name] = _ORIGINS[-1]
            if applies is not None:
                self._applies[name] = applies
            return item

        return decorate

    def unregister(self, name: str) -> None:
        self._items.pop(name, None)
        self._applies.pop(name, None)
        self._origins.pop(name, None)

    def origin(self, name: str) -> str:
        """Where ``name`` was registered: ``built-in``, ``file PATH`` or ``plugin DIST``."""
        self.get(name)
        return self._origins[name]

    def why_not(self, name: str, **context) -> str | None:
        """The reason ``name`` does not apply to ``context``, or None."""
        self.get(name)
        check = self._applies.get(name)
        return check(**context) if check is not None else None

    def names(self) -> list[str]:
        return sorted(self._items)

    def descriptions(self) -> dict[str, str]:
        return {name: self._items[name][1] for name in self.names()}

    def get(self, name: str) -> Any:
        if name not in self._items:
            raise KeyError(f"unknown {self.kind} {name!r}; valid {self.kind}s: "
                           f"{', '.join(self.names())}")
        return self._items[name][0]


SCENES = Registry("scene")
register_scene = SCENES.register
scene_names = SCENES.names
scene_descriptions = SCENES.descriptions


def get_scene(name: str, **parameters):
    """Build the scene ``name`` from its factory with the given parameters."""
    return SCENES.get(name)(**parameters)
