"""Formulation registry: name -> ``discretise(scene, mesh) -> Discretisation``."""

from scenes.registry import Registry

FORMULATIONS = Registry("formulation")
formulation_names = FORMULATIONS.names
formulation_descriptions = FORMULATIONS.descriptions
get_formulation = FORMULATIONS.get


def frictionless_only(kind: str, name: str, applies=None):
    """``applies`` (or nothing) plus the refusal of a scene with friction, for a ``kind``
    ('formulation', 'estimator') ``name`` that does not model it (docs/theory.md, 17)."""
    def check(scene=None, **context) -> str | None:
        if scene is not None and scene.friction.active:
            return (f"{kind} {name!r} does not model friction (the scene's law is "
                    f"{scene.friction.label})")
        return applies(scene=scene, **context) if applies is not None else None

    return check


def register_formulation(name: str, description: str, applies=None, *,
                         friction: bool = False):
    """Register ``discretise(scene, mesh, **options)`` under ``name``; ``applies(scene=...)``
    says why a scene is refused (optional); ``friction``: whether it models a scene's
    friction law (else a scene with friction is refused with that reason)."""
    check = applies if friction else frictionless_only("formulation", name, applies)
    return FORMULATIONS.register(name, description, check, meta={"friction": bool(friction)})
