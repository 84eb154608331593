"""One sequence of a run, fully specified: ``SequenceSpec``. Its ``key`` hashes everything that
determines its rows, so a rerun can tell a finished sequence from one to compute, and its
partition of the result store is named by it. Parameter sweeps (``paper:poisson_ratio=0.3|0.45``)
are parsed here into one spec per value."""

from __future__ import annotations

import hashlib
import inspect
import itertools
import json
from dataclasses import dataclass, fields, replace

from bench.sequence.loop import LoopConfig
from bench.sequence.memory import memory_refusal
from formulations import get_formulation
from formulations.cells import DEFAULT_CELL, family_for
from formulations.elasticity import why_no_element
from formulations.registry import FORMULATIONS
from scenes import SceneError, get_scene
from scenes.budget import dof_budget
from scenes.registry import SCENES

SPEC_VERSION = 3  # bump when the rows of an unchanged spec would change (3: P3 references)


@dataclass(frozen=True, eq=False)
class SequenceSpec:
    """A sequence: what it combines (scene, formulation, solver, estimator, with their sweep
    parameters), how its loop runs (``loop``: strategy, order, budgets, marking, back-end,
    target error) and what its errors are measured against."""

    scene: str
    formulation: str
    solver: str
    estimator: str
    loop: LoopConfig
    scene_parameters: tuple[tuple[str, object], ...] = ()
    formulation_options: tuple[tuple[str, object], ...] = ()
    reference_dofs: int | None = None
    crosscheck_dofs: int = 0
    scene_source: str = ""  # digest of the --scene-file files ('' without)

    strategy = property(lambda self: self.loop.strategy)
    order = property(lambda self: self.loop.order)
    cell = property(lambda self: self.loop.cell)
    max_dofs = property(lambda self: self.loop.max_dofs)
    backend = property(lambda self: self.loop.options().get("backend"))

    @property
    def key(self) -> str:
        """A hash of every field that determines the rows: the spec's own and every field of
        its loop but where it runs (``max_memory_gib``), so a new loop field is keyed
        without an edit here."""
        loop = {f.name: getattr(self.loop, f.name) for f in fields(self.loop)
                if f.name != "max_memory_gib"}
        own = {f.name: getattr(self, f.name) for f in fields(self) if f.name != "loop"}
        text = json.dumps({**own, "loop": loop, "version": SPEC_VERSION}, sort_keys=True,
                          default=str)
        return hashlib.sha256(text.encode()).hexdigest()[:20]

    @property
    def legacy_key(self) -> str:
        """The key of the same spec before it hashed its loop's fields (results folders
        written then are still read: ``bench.matrix.run``)."""
        loop = self.loop
        flat = {"scene": self.scene, "formulation": self.formulation, "solver": self.solver,
                "estimator": self.estimator, "strategy": loop.strategy, "order": loop.order,
                "scene_parameters": self.scene_parameters,
                "formulation_options": self.formulation_options, "max_dofs": loop.max_dofs,
                "max_levels": loop.max_levels, "marking": loop.marking, "theta": loop.theta,
                "nested": loop.nested, "backend": self.backend,
                "reference_dofs": self.reference_dofs, "crosscheck_dofs": self.crosscheck_dofs}
        if self.scene_source:
            flat["scene_source"] = self.scene_source
        if loop.target_error:
            flat["target_error"] = loop.target_error
        if loop.cell != DEFAULT_CELL:
            flat["cell"] = loop.cell
        text = json.dumps({**flat, "version": SPEC_VERSION}, sort_keys=True, default=str)
        return hashlib.sha256(text.encode()).hexdigest()[:20]

    def loop_config(self, max_memory_gib: float | None = None) -> LoopConfig:
        return replace(self.loop, max_memory_gib=max_memory_gib)

    @property
    def labels(self) -> dict[str, str]:
        """The sweep columns of the rows: 'name=value:name=value', empty for the defaults."""
        return {"scene_parameters": label(self.scene_parameters),
                "formulation_options": label(self.formulation_options)}


def cross_product(scenes, formulations, solvers, estimators, strategies, orders, loop: dict,
                  cells=(DEFAULT_CELL,), **settings) -> list[SequenceSpec]:
    """Every combination as a spec; ``scenes`` and ``formulations`` are (name, parameter
    pairs) as ``parse_item`` gives them, ``loop`` the ``LoopSettings`` values every spec
    shares (with its own strategy, order and cell), ``settings`` the remaining fields."""
    return [SequenceSpec(scene=scene, formulation=formulation, solver=solver,
                         estimator=estimator,
                         loop=LoopConfig(**loop, strategy=strategy, order=order, cell=cell),
                         scene_parameters=tuple(sorted(parameters)),
                         formulation_options=tuple(sorted(options)), **settings)
            for (scene, parameters), (formulation, options), solver, estimator, strategy, order,
            cell in itertools.product(scenes, formulations, solvers, estimators, strategies,
                                      orders, cells)]


def why_no_cells(spec: SequenceSpec, scene) -> str | None:
    """Why the spec's cells cannot carry ``scene`` (no family of that shape in its dimension,
    the family's own refusal, or no element of the order), or None."""
    try:
        family = family_for(spec.cell, scene.dim)
    except ValueError as error:
        return str(error)
    return (family.why_not(scene, spec.strategy)
            or why_no_element(spec.order, scene.dim, spec.cell))


def label(pairs) -> str:
    return ":".join(f"{k}={v}" for k, v in pairs)


def parse_value(text: str):
    """A sweep value as written: int, else float, else the string."""
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text


def parse_item(item: str, kind: str) -> list[tuple[str, tuple]]:
    """'name:key=v1|v2:other=w' -> one (name, ((key, v), (other, w))) per combination of
    values; the name alone gives (name, ())."""
    name, *parts = item.split(":")
    names, values = [], []
    for part in parts:
        key, sep, choices = part.partition("=")
        if not sep or not key or not choices:
            raise ValueError(f"{kind}={item!r}: {part!r} is not key=value or key=v1|v2")
        names.append(key.strip())
        values.append([parse_value(v.strip()) for v in choices.split("|")])
    return [(name.strip(), tuple(zip(names, combo, strict=True)))
            for combo in itertools.product(*values)]


def check_parameters(kind: str, name: str, pairs, function) -> None:
    """Refuse a parameter the scene factory or ``discretise`` does not take, listing those
    it does."""
    accepted = [p for p in inspect.signature(function).parameters
                if p not in ("scene", "mesh")]
    unknown = [k for k, _ in pairs if k not in accepted]
    if unknown:
        raise ValueError(f"{kind} {name!r} has no parameter {', '.join(map(repr, unknown))}; "
                         f"its parameters: {', '.join(accepted) or '(none)'}")


def build_scene(spec: SequenceSpec):
    """The spec's scene, its parameters checked by name here and by value by the scene, its
    starting mesh within the spec's DOF budget (``scenes.budget``)."""
    check_parameters("scene", spec.scene, spec.scene_parameters, SCENES.get(spec.scene))
    try:
        with dof_budget(spec.max_dofs):
            return get_scene(spec.scene, **dict(spec.scene_parameters))
    except SceneError as error:
        where = label(spec.scene_parameters)
        raise SceneError(f"scene {spec.scene!r}{f' ({where})' if where else ''}: {error}") \
            from None


def check_formulation_options(spec: SequenceSpec, scene=None) -> None:
    """Refuse an option ``discretise`` does not take; the order is its own dimension. With the
    spec's ``scene``, also every value: the formulation discretises the scene's coarsest mesh
    with them, so its own checks refuse a bad value before any run."""
    if any(k == "order" for k, _ in spec.formulation_options):
        raise ValueError(f"formulation {spec.formulation!r}: give the polynomial order with "
                         "--order (RunConfig.orders), not as a formulation option")
    discretise = get_formulation(spec.formulation)
    check_parameters("formulation", spec.formulation, spec.formulation_options, discretise)
    family = family_for(spec.cell, scene.dim) if scene is not None else None
    if scene is not None and why_no_cells(spec, scene) is None and FORMULATIONS.why_not(
            spec.formulation, scene=scene, family=family) is None:  # else a skipped row
        mesh = family.starting_mesh(scene)
        try:
            discretise(scene, mesh, order=spec.order, **dict(spec.formulation_options))
        except (ValueError, TypeError) as error:
            raise ValueError(f"formulation {spec.formulation!r}: {error}") from None


def check_level_zero(spec: SequenceSpec, scene, max_memory_gib: float | None) -> None:
    """Refuse (ValueError) a sequence whose starting mesh is already over its DOF budget or
    would not fit in memory: the budgets count from level 0."""
    if why_no_cells(spec, scene) is not None:
        return  # a skipped row, nothing is built
    family = family_for(spec.cell, scene.dim)
    ndofs = family.count_free_dofs(scene, family.starting_mesh(scene), spec.order)
    where = f"scene {spec.scene!r}" + (f" ({spec.labels['scene_parameters']})"
                                       if spec.scene_parameters else "")
    if ndofs > spec.max_dofs:
        raise ValueError(f"{where} starts with {ndofs:,} DOFs at P{spec.order}, over "
                         f"max_dofs={spec.max_dofs:,}; give a coarser starting mesh or "
                         f"max_dofs >= {ndofs:,}")
    refusal = memory_refusal(0, ndofs, spec.solver, spec.loop_config(max_memory_gib),
                             scene.dim)
    if refusal is not None:
        raise ValueError(f"{where}: {refusal}; give a coarser starting mesh or a larger "
                         "max_memory_gib")
