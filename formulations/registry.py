"""Formulation registry: name -> ``discretise(scene, mesh) -> Discretisation``."""

import inspect

from scenes.registry import Registry

FORMULATIONS = Registry("formulation")
formulation_names = FORMULATIONS.names
formulation_descriptions = FORMULATIONS.descriptions
get_formulation = FORMULATIONS.get


def friction_dims(friction) -> tuple[int, ...]:
    """The dimensions a registration models friction in: True is 2D, False none, or a tuple."""
    if friction is True:
        return (2,)
    if friction is False:
        return ()
    return tuple(int(d) for d in friction)


def frictionless_only(kind: str, name: str, applies=None, dims: tuple[int, ...] = ()):
    """``applies`` (or nothing) plus the refusal of a scene with friction in a dimension not in
    ``dims``, for a ``kind`` ('formulation', 'estimator') ``name`` (docs/theory.md, 17)."""
    def check(scene=None, **context) -> str | None:
        if scene is not None and scene.friction.active and scene.dim not in dims:
            where = f" in {scene.dim}D" if dims else ""
            return (f"{kind} {name!r} does not model friction{where} (the scene's law is "
                    f"{scene.friction.label})")
        if applies is None:
            return None
        accepted = inspect.signature(applies).parameters  # a plugin's may take scene only
        if not any(p.kind is p.VAR_KEYWORD for p in accepted.values()):
            context = {k: v for k, v in context.items() if k in accepted}
        return applies(scene=scene, **context)

    return check


def register_formulation(name: str, description: str, applies=None, *,
                         friction: bool | tuple[int, ...] = False, traits: tuple[str, ...] = ()):
    """Register ``discretise(scene, mesh, **options)`` under ``name``; ``applies(scene=...,
    family=...)`` says why a scene or a cell family (``formulations.cells``) is refused
    (optional; it may take either keyword only); ``friction``: whether it models a scene's
    friction law (True: in 2D; or the dimensions, e.g. (2, 3)), else a scene with friction is
    refused with that reason; ``traits``: what an estimator may ask of it (TRAITS)."""
    unknown = [t for t in traits if t not in TRAITS]
    if unknown:
        raise ValueError(f"traits={list(traits)!r}: unknown {', '.join(unknown)}; valid: "
                         f"{', '.join(TRAITS)}")
    dims = friction_dims(friction)
    check = frictionless_only("formulation", name, applies, dims)
    return FORMULATIONS.register(name, description, check,
                                 meta={"friction": bool(dims), "friction_dims": dims,
                                       "traits": tuple(traits)})


# what a formulation may declare of itself, for estimators whose theory needs it
# (docs/plugins.md, "Traits")
TRAITS = {
    "nitsche-contact": "its pressure is Nitsche's lambda_h = -[P_gamma(u_h)]_- and its contact "
                       "residual sigma_nn(u_h) + lambda_h (nitsche-residual applies)",
}


def formulation_traits(name: str) -> tuple[str, ...]:
    """The traits the formulation ``name`` declared (none for an unknown name)."""
    return tuple(FORMULATIONS.meta(name, "traits", ()) if name in FORMULATIONS.names() else ())
