"""``RunConfig``: one description of a run of the matrix, read alike by the command line
(``bench.cli.generated`` builds ``run``'s options from its fields), run files
(``bench.matrix.config_files``), ``compare``, the gates and the study (docs/command-line.md,
"Run files"). Its fields fall in three sections: what runs, how each sequence runs (the
loop's ``LoopSettings``, inherited, so declared once) and where it runs."""

from __future__ import annotations

from dataclasses import dataclass, fields, replace

from bench.matrix.distributed import scheduler_endpoint
from bench.matrix.plugins import load_plugins
from bench.matrix.scene_files import load_scene_files, source_digest
from bench.matrix.spec import SequenceSpec, cross_product, parse_item
from bench.sequence.loop import STRATEGIES, LoopSettings
from bench.sequence.options import option, option_fields
from estimators import estimator_names, guaranteed_estimators
from formulations import formulation_names, solver_names
from formulations.cells import DEFAULT_CELL, cell_names, check_cell
from formulations.elasticity import ORDERS, check_order
from formulations.solvers.registry import FAST_SOLVER, REFERENCE_SOLVER
from scenes import scene_names
from scenes.base import is_integer

NAME_LISTS = {"scenes": scene_names, "formulations": formulation_names,
              "solvers": solver_names, "estimators": estimator_names,
              "strategies": lambda: list(STRATEGIES)}
SWEPT = ("scenes", "formulations")  # lists whose items may carry name:key=v1|v2 sweeps


def _what(default, help: str, flag: str, kind: str, **more):
    return option(default, help, flag=flag, kind=kind, section="what", **more)


def _where(default, help: str, flag: str, kind: str, **more):
    return option(default, help, flag=flag, kind=kind, section="where", **more)


@dataclass(frozen=True)
class RunConfig(LoopSettings):
    """Everything that determines a run of the matrix (the options of ``python -m bench run``,
    the keys of a run file). Name lists are checked against the registries on construction; a
    scene or formulation may carry a sweep, ``paper:poisson_ratio=0.3|0.45``."""

    scenes: tuple[str, ...] = _what(
        ("paper",), "scene(s), comma-separated; sweep parameters with name:key=v1|v2, e.g. "
        "paper:poisson_ratio=0.3|0.45", "scene", "scenes")
    formulations: tuple[str, ...] = _what(
        ("mixed",), "formulation(s); options as for --scene, e.g. mixed:h_over_H=0.5|0.25",
        "formulation", "formulations")
    solvers: tuple[str, ...] = _what(
        (FAST_SOLVER,), f"solver(s) ({FAST_SOLVER} is the fast one; {REFERENCE_SOLVER} is the "
        f"interior-point judge every fast solve is checked against: --solver {FAST_SOLVER},"
        f"{REFERENCE_SOLVER} runs both)", "solver", "solvers")
    estimators: tuple[str, ...] = _what(("residual",), "estimator(s)", "estimator",
                                        "estimators")
    strategies: tuple[str, ...] = _what(("adaptive",), "refinement strategy(ies)", "strategy",
                                        "strategies")
    orders: tuple[int, ...] = _what(
        (1,), "polynomial order(s) p of the displacements, comma-separated; every "
        "formulation and estimator runs at each", "order", "orders")
    cells: tuple[str, ...] = _what(
        (DEFAULT_CELL,), "cell shape(s), comma-separated (tri: triangles, tetrahedra in 3D; "
        "quad: quadrilaterals with hanging nodes, hexahedra in 3D); every formulation and "
        "estimator runs on each", "cell", "cells")
    reference_dofs: int | None = _what(
        None, "measure errors of scenes without an exact solution against a cached adaptive "
        "P3 reference (mixed method) with at most this many DOFs", "reference-dofs", "int>0",
        default_text="only scenes with an exact solution get errors")
    reference_crosscheck: bool = _what(
        False, "also build the P2 reference (twice the budget) and record its agreement with "
        "the P3 one in truth.json", "reference-crosscheck", "switch")
    crosscheck_dofs: int = _what(
        0, "also solve levels with at most this many DOFs with the reference solver and "
        "record the differences (0: never)", "crosscheck-dofs", "int>=0")
    timing_repeats: int = _what(
        0, "time again, this many times more each, the sequences that may be the cheapest to "
        "a relative error of 1e-2 or 1e-3, for a cost that ranks (docs/report.md, \"Cost and "
        "ties\"); compare: 3", "timing-repeats", "int>=0")
    scene_files: tuple[str, ...] = _what(
        (), "a Python file that registers scenes with scenes.register_scene, or a TOML scene "
        "(docs/scenes.md) (repeatable); its scenes join --scene's choices", "scene-file",
        "files", metavar="FILE", default_text="none")
    out: str = _where("results", "output folder for results.parquet and results.csv", "out",
                      "text")
    overwrite: bool = _where(
        False, "delete earlier results in OUT first (kept until the new run has finished a "
        "sequence; without it every sequence an earlier run finished with the same settings "
        "is reused); an action of the command line, never read from or saved to a run file",
        "overwrite", "switch", saved=False)
    workers: int = _where(
        0, "run the sequences on a local Dask cluster of this many processes (one thread "
        "each; 0: in this process)", "workers", "int>=0")
    scheduler: str | None = _where(
        None, "run the sequences on the existing Dask cluster at ADDRESS, e.g. "
        "tcp://10.0.0.5:8786 (its workers need this package and --cache on shared "
        "storage); refused if no scheduler answers there within 10 s", "scheduler",
        "scheduler", metavar="ADDRESS", default_text="none")
    cache: str | None = _where(
        None, "folder of the cached overkill references", "cache", "text", metavar="DIR",
        default_text="$SIGNORINI_BENCH_CACHE or .cache/references")
    command: str = ""  # how the run was asked for, recorded in run.json
    # the run as a union of matrices (docs/command-line.md, "Runs in parts"): each part is this
    # run with the part's fields (pairs of field name and value) in place of its own; empty:
    # the run is its own one matrix
    parts: tuple[tuple[tuple[str, object], ...], ...] = ()

    def __post_init__(self):
        super().__post_init__()  # the loop's settings
        object.__setattr__(self, "scene_files", tuple(str(f) for f in self.scene_files))
        load_plugins()
        load_scene_files(self.scene_files)  # their scenes are valid names from here on
        for name, valid in NAME_LISTS.items():
            self._check_names(name, valid())
        self._check_axis("orders", "order", list(map(str, ORDERS)), check_order)
        self._check_axis("cells", "cell", cell_names(), check_cell)
        for name in ("reference_dofs", "crosscheck_dofs", "workers", "timing_repeats"):
            value = getattr(self, name)
            if value is not None and not (is_integer(value) and value >= 0):
                raise ValueError(f"{name}={value!r} is not an integer >= 0")
        if not str(self.out).strip():
            raise ValueError(f"out={self.out!r} is empty; give an output folder")
        if self.scheduler is not None:
            scheduler_endpoint(self.scheduler)
        if self.backend is not None and set(self.solvers) == {REFERENCE_SOLVER}:
            raise ValueError(f"backend={self.backend!r} applies to the fast solvers "
                             f"({', '.join(s for s in solver_names() if s != REFERENCE_SOLVER)}"
                             f"); solver={REFERENCE_SOLVER!r} (Clarabel) uses its own linear "
                             "algebra: leave out the backend or add a fast solver")
        self._check_parts()
        unsafe = [e for e in self.estimators if e not in guaranteed_estimators()]
        if self.target_error is not None and unsafe:
            raise ValueError(f"target_error={self.target_error!r} needs estimators whose eta is "
                             f"a guaranteed bound ({', '.join(guaranteed_estimators())}); "
                             f"{', '.join(unsafe)} bound the error only up to a constant")

    def _check_names(self, name: str, valid: list[str]) -> None:
        """A list of registered names, each once; sweeps parsed."""
        given = getattr(self, name)
        items = (given,) if isinstance(given, str) else tuple(given)
        object.__setattr__(self, name, items)
        names = [item.split(":")[0] for item in items] if name in SWEPT else list(items)
        unknown = [n for n in names if n not in valid]
        if not items or unknown:
            raise ValueError(f"{name}={list(items)!r}: unknown "
                             f"{', '.join(unknown) or '(none)'}; valid: {', '.join(valid)}")
        if len(set(items)) < len(items):
            raise ValueError(f"{name}={list(items)!r} names an item twice")
        if name in SWEPT:
            for item in items:
                parse_item(item, name)

    def _check_axis(self, name: str, one: str, allowed: list[str], check) -> None:
        """A matrix axis (orders, cells): a non-empty tuple naming each value once, each one
        passing ``check``."""
        given = getattr(self, name)
        values = (given,) if isinstance(given, (str, int)) else tuple(given)
        object.__setattr__(self, name, values)
        if not values or len(set(values)) < len(values):
            raise ValueError(f"{name}={list(values)!r}: give each {one} once, from "
                             f"{', '.join(allowed)}")
        for value in values:
            check(value)

    def specs(self) -> list[SequenceSpec]:
        """Every sequence of the run: its one matrix, or the union of its parts' (a sequence
        two parts share runs once, in the first part's place)."""
        if self.parts:
            unique = {}
            for part in self.part_configs():
                for spec in part.specs():
                    unique.setdefault(spec.key, spec)
            return list(unique.values())
        return cross_product(
            [s for item in self.scenes for s in parse_item(item, "scenes")],
            [f for item in self.formulations for f in parse_item(item, "formulations")],
            self.solvers, self.estimators, self.strategies, self.orders, self.settings(),
            cells=self.cells,
            reference_dofs=self.reference_dofs, crosscheck_dofs=self.crosscheck_dofs,
            scene_source=source_digest(self.scene_files))

    def part_configs(self) -> list[RunConfig]:
        """Each part as a run of its own (what runs and how; never where)."""
        return [replace(self, **dict(part), parts=(), command="") for part in self.parts]

    def _check_parts(self) -> None:
        """Parts name what runs and how each sequence runs, never where (one folder, one
        cluster); each is checked as a run of its own."""
        own = {f.name: o for f, o in option_fields(self)}
        parts = tuple(tuple(sorted((dict(part) if not isinstance(part, dict) else part).items()))
                      for part in self.parts)
        object.__setattr__(self, "parts", parts)
        for k, part in enumerate(parts):
            bad = [name for name, _ in part if name not in own or own[name].section == "where"]
            if bad or not part:
                allowed = ", ".join(o.flag for o in own.values() if o.section != "where")
                raise ValueError(f"parts[{k}] sets {', '.join(bad) or 'nothing'}; a part sets "
                                 f"one or more of: {allowed}")
        self.part_configs()  # each part's names and values checked as a run's

    def record(self) -> dict:
        """The configuration as written to run.json (every field but ``command``; a run file
        holding it repeats the run, ``bench.matrix.config_files``)."""
        unsaved = {f.name for f, o in option_fields(self) if not o.saved}
        record = {f.name: getattr(self, f.name) for f in fields(self)
                  if f.name != "command" and f.name not in unsaved}
        record["parts"] = [dict(part) for part in self.parts]
        return record
