"""Declarative scenes: a TOML file describes the body (a rectangle or a mesh file), the material,
which boundary is clamped, in contact or loaded, and the gap and loads as expressions of x and y
(docs/scenes.md). ``register_toml_scene(path)`` validates it and registers it like a built-in
scene; every error is one line naming the file, the key and what is allowed."""

from __future__ import annotations

import hashlib
import inspect
import tomllib
from pathlib import Path

import numpy as np

from scenes.base import Material, Scene, SceneError, is_integer, is_number
from scenes.budget import LOAD_VERTICES, tensor_mesh, vertex_budget
from scenes.expressions import Expression, ExpressionError
from scenes.friction import LAWS, FrictionLaw, friction_law
from scenes.mesh_file import on_segments, read_mesh_file
from scenes.registry import register_scene

SIDES = ("left", "right", "bottom", "top")
TABLES = {"geometry": ("rectangle", "divisions", "mesh"),
          "material": ("young_modulus", "poisson_ratio", "plane"),
          "boundary": ("clamped", "contact", "loaded"),
          "contact": ("gap", "coordinate"),
          "load": ("traction", "body_force", "load_jump"),
          "friction": ("law", "mu", "slip_bound", "slide"),
          "parameters": None}
TOP_LEVEL = ("name", "description", "tags")


def register_toml_scene(path: str | Path) -> str:
    """Read, check and register the scene of ``path``; its name. SceneError on bad input."""
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text())
    except (OSError, tomllib.TOMLDecodeError, UnicodeDecodeError) as error:
        raise SceneError(f"{path}: not a readable TOML file: {error}") from None
    _check_keys(path, data)
    name = data.get("name")
    if not (isinstance(name, str) and name and name.replace("-", "").replace("_", "").isalnum()):
        raise SceneError(f"{path}: name={name!r} is not a non-empty name of letters, digits, "
                         "'-' and '_'")
    description = str(data.get("description", f"scene from {path.name}"))
    defaults = _parameters(path, data.get("parameters", {}))
    digest = hashlib.sha256(path.read_bytes())
    mesh_name = data.get("geometry", {}).get("mesh")
    if isinstance(mesh_name, str) and (path.parent / mesh_name).is_file():
        digest.update((path.parent / mesh_name).read_bytes())

    def factory(**parameters) -> Scene:
        unknown = sorted(set(parameters) - set(defaults))
        if unknown:
            raise SceneError(f"{path}: parameter {unknown[0]!r} is not one of its [parameters] "
                             f"({', '.join(defaults) or 'none'})")
        values = {**defaults, **_parameters(path, parameters)}
        return _scene(path, data, name, description, values, digest.hexdigest()[:16])

    factory.__signature__ = _signature(defaults)
    with vertex_budget(LOAD_VERTICES, "a scene file's check on loading"):
        scene = factory()  # refuse a bad file now, not at the first solve
    register_scene(name, description, tags=scene.tags, dim=scene.dim)(factory)
    return name


def _check_keys(path: Path, data: dict) -> None:
    for key, value in data.items():
        if key not in TABLES and key not in TOP_LEVEL:
            raise SceneError(f"{path}: key {key!r} is not one of "
                             f"{', '.join((*TOP_LEVEL, *TABLES))}")
        allowed = TABLES.get(key)
        if key in TABLES and not isinstance(value, dict):
            raise SceneError(f"{path}: {key!r} is not a table ([{key}])")
        for inner in value if allowed is not None else ():
            if inner not in allowed:
                raise SceneError(f"{path}: [{key}] {inner} is not one of {', '.join(allowed)}")


def _parameters(path: Path, table: dict) -> dict[str, float]:
    for key, value in table.items():
        if not (is_number(value) and np.isfinite(value)) or key in ("x", "y", "pi", "e"):
            raise SceneError(f"{path}: [parameters] {key}={value!r} is not a finite number "
                             "with a name other than x, y, pi, e")
    return {key: float(value) for key, value in table.items()}


def _signature(defaults: dict[str, float]) -> inspect.Signature:
    """The factory's keyword parameters, so that sweeps check names as for built-in scenes."""
    return inspect.Signature([inspect.Parameter(k, inspect.Parameter.KEYWORD_ONLY, default=v)
                              for k, v in defaults.items()])


def _scene(path, data, name, description, values, digest) -> Scene:
    geometry, boundary = data.get("geometry", {}), data.get("boundary", {})
    mesh, part = _body(path, geometry)
    where = f"{path}: [boundary]"
    is_dirichlet = part(boundary.get("clamped"), f"{where} clamped", required=True)
    is_contact = part(boundary.get("contact"), f"{where} contact", required=True)
    loaded = part(boundary.get("loaded"), f"{where} loaded", required=False)
    contact = data.get("contact", {})
    load = data.get("load", {})
    try:
        gap = _expression(contact.get("gap"), values, f"{path}: [contact] gap", required=True)
        coordinate = _expression(contact.get("coordinate", "x"), values,
                                 f"{path}: [contact] coordinate")
        traction = _vector(load.get("traction"), values, f"{path}: [load] traction")
        body_force = _vector(load.get("body_force"), values, f"{path}: [load] body_force")
        load_jump = _expression(load.get("load_jump"), values, f"{path}: [load] load_jump")
        friction = _friction(path, data.get("friction", {}), values)
    except ExpressionError as error:
        raise SceneError(str(error)) from None
    if traction is not None and loaded is None:
        raise SceneError(f"{path}: [load] traction needs [boundary] loaded (where it acts)")
    material = data.get("material", {})
    return Scene(
        name=name, description=description, mesh=mesh,
        material=Material(material.get("young_modulus", 1.0),
                          material.get("poisson_ratio", 0.3), material.get("plane", "strain")),
        is_dirichlet=is_dirichlet, is_contact=is_contact, gap=gap,
        contact_coordinate=coordinate, body_force=body_force,
        traction=None if traction is None else _only_on(loaded, traction),
        parameters={**values, "source": digest}, tags=tuple(data.get("tags", ())),
        friction=friction, load_jump=load_jump)


def _friction(path: Path, table: dict, values) -> FrictionLaw:
    """[friction]: ``law`` (none, tresca, coulomb), Coulomb's ``mu`` and the obstacle's
    ``slide`` (constants of the parameters), Tresca's ``slip_bound`` s(x, y)."""
    where = f"{path}: [friction]"
    law = table.get("law", "none")
    if law not in LAWS:
        raise SceneError(f"{where} law={law!r} is not one of {', '.join(LAWS)}")
    mu, slide = (_expression(table.get(key, 0), values, f"{where} {key}").constant()
                 for key in ("mu", "slide"))
    bound = table.get("slip_bound")
    if bound is not None and law != "tresca":
        raise SceneError(f"{where} slip_bound needs law='tresca' (law={law!r})")
    if law == "tresca" and bound is None:
        raise SceneError(f"{where} law='tresca' needs slip_bound (an expression of x and y)")
    function = None if bound is None else _expression(bound, values, f"{where} slip_bound")
    try:
        return friction_law(law, mu, tresca_bound=function, slide=slide)
    except SceneError as error:
        raise SceneError(f"{where} {error}") from None


def _body(path: Path, geometry: dict):
    """The initial mesh and a function turning a [boundary] entry into a predicate."""
    if ("mesh" in geometry) == ("rectangle" in geometry):
        raise SceneError(f"{path}: [geometry] needs exactly one of rectangle, mesh")
    if "mesh" in geometry:
        source = read_mesh_file(path.parent / str(geometry["mesh"]),
                                f"{path}: [geometry] mesh")
        size = np.ptp(source.mesh.p, axis=1).max()
        predicates = {k: on_segments(v, 1e-8 * size) for k, v in source.groups.items()}
        return source.mesh, _named_parts(predicates, "physical group names in the mesh")
    box = geometry["rectangle"]
    good = (isinstance(box, list) and len(box) == 2
            and all(isinstance(r, list) and len(r) == 2 and all(is_number(v) for v in r)
                    and r[0] < r[1] for r in box))
    if not good:
        raise SceneError(f"{path}: [geometry] rectangle={box!r} is not [[x0, x1], [y0, y1]] "
                         "with x0 < x1 and y0 < y1")
    divisions = geometry.get("divisions", [4, 4])
    if not (isinstance(divisions, list) and len(divisions) == 2
            and all(is_integer(n) and n >= 1 for n in divisions)):
        raise SceneError(f"{path}: [geometry] divisions={divisions!r} is not [nx, ny] of "
                         "integers >= 1")
    (x0, x1), (y0, y1) = box
    mesh = tensor_mesh(np.linspace(x0, x1, divisions[0] + 1),
                               np.linspace(y0, y1, divisions[1] + 1))
    tol = 1e-10 * max(x1 - x0, y1 - y0)
    sides = {"left": lambda x: np.abs(x[0] - x0) < tol, "right": lambda x: np.abs(x[0] - x1) < tol,
             "bottom": lambda x: np.abs(x[1] - y0) < tol, "top": lambda x: np.abs(x[1] - y1) < tol}
    return mesh, _named_parts(sides, "sides of the rectangle")


def _named_parts(predicates: dict, kind: str):
    def part(value, where: str, required: bool):
        if value is None and not required:
            return None
        names = [value] if isinstance(value, str) else value
        if not (isinstance(names, list) and names and all(n in predicates for n in names)):
            raise SceneError(f"{where}={value!r} is not one or a list of the {kind}: "
                             f"{', '.join(predicates)}")
        chosen = [predicates[n] for n in names]
        return lambda x: np.logical_or.reduce([p(x) for p in chosen])
    return part


def _expression(text, values, where: str, required: bool = False):
    if text is None:
        if required:
            raise SceneError(f"{where} is missing (an expression of x and y)")
        return None
    return Expression(text, values, where)


def _vector(texts, values, where: str):
    if texts is None:
        return None
    if not (isinstance(texts, list) and len(texts) == 2):
        raise SceneError(f"{where}={texts!r} is not a list of two expressions [x part, y part]")
    parts = [Expression(t, values, f"{where}[{k}]") for k, t in enumerate(texts)]
    return lambda x: np.stack([p(x) for p in parts])


def _only_on(predicate, traction):
    return lambda x: np.where(predicate(x), traction(x), 0.0)
