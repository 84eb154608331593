"""Command-line options generated from the fields of ``RunConfig`` (``bench.sequence.options``):
each option's name, type, default and help come from its field, so a default is written once
and a new field needs no parser edit; ``run_values`` turns parsed arguments back into fields."""

from __future__ import annotations

import argparse
from dataclasses import Field

from bench.cli.option_types import (
    cell_list,
    gib,
    name_list,
    non_negative_int,
    order_list,
    positive_float,
    positive_int,
    scheduler_address,
    theta_value,
)
from bench.matrix.config import NAME_LISTS
from bench.sequence.options import Option, field_default, option_fields
from scenes.registry import SCENES

ONE = {"scenes": "scene", "formulations": "formulation", "solvers": "solver",
       "estimators": "estimator", "strategies": "strategy"}  # one item of each name list


def broken_scenes() -> dict[str, str]:
    """Why each scene that failed to load is left out (its origin and error)."""
    return {b.name: f"{b.origin}: {b.reason}" for b in SCENES.broken()}


def _names(kind: str):
    return name_list(ONE[kind], NAME_LISTS[kind](), plural=kind, sweep=kind in (
        "scenes", "formulations"), broken=broken_scenes() if kind == "scenes" else None)


TYPES = {"orders": lambda name: order_list, "cells": lambda name: cell_list,
         "int>0": positive_int, "int>=0": non_negative_int, "float>0": positive_float,
         "theta": lambda name: theta_value, "gib": lambda name: gib,
         "scheduler": lambda name: scheduler_address, "text": lambda name: str,
         **{kind: lambda name, kind=kind: _names(kind) for kind in NAME_LISTS}}


def dest(opt: Option) -> str:
    return opt.flag.replace("-", "_")


def _shown(value) -> str:
    if isinstance(value, (tuple, list)):
        return ",".join(map(str, value))
    return str(value)


def _help(opt: Option, default, help: str | tuple[str, str] | None) -> str:
    """The option's help and its default; ``help``: a command's own help, or its help and the
    words for its default."""
    text, words = help if isinstance(help, tuple) else (help or opt.help, None)
    if opt.kind in NAME_LISTS:
        text += f"; one of: {', '.join(NAME_LISTS[opt.kind]())}"
    if opt.kind not in ("switch", "switch-off"):
        unset = default is None or default == ()
        words = words or (opt.default_text if unset and opt.default_text else _shown(default))
        text += f" (default: {words})"
    return text.replace("%", "%%")


def add_option(parser, field: Field, opt: Option, default, help: str | None = None) -> None:
    """``parser.add_argument`` for one field, with ``default`` (the field's, or a command's
    own)."""
    flag, text = f"--{opt.flag}", _help(opt, default, help)
    if opt.kind == "switch":
        parser.add_argument(flag, action="store_true", default=bool(default), help=text)
    elif opt.kind == "switch-off":
        parser.add_argument(flag, dest=dest(opt), action="store_true",
                            default=not default, help=text)
    elif opt.kind == "files":
        parser.add_argument(flag, action="append", default=list(default), metavar=opt.metavar,
                            help=text)
    elif opt.kind == "choice":
        parser.add_argument(flag, choices=opt.choices(), default=default, help=text)
    else:
        parser.add_argument(flag, type=TYPES[opt.kind](field.name), default=default,
                            metavar=opt.metavar, help=text)


def add_run_options(parser, cls, defaults: dict | None = None, only: tuple[str, ...] = (),
                    helps: dict | None = None) -> None:
    """The options of ``cls``' fields (``only`` these, by field name, if given), with the
    fields' defaults or ``defaults`` (by field name) and ``helps`` in place of their help."""
    defaults, helps = defaults or {}, helps or {}
    for field, opt in option_fields(cls):
        if only and field.name not in only:
            continue
        default = defaults.get(field.name, field_default(field))
        add_option(parser, field, opt, default, helps.get(field.name))


def run_values(args: argparse.Namespace, cls) -> dict:
    """The fields of ``cls`` whose options ``args`` holds, by field name."""
    values = {}
    for field, opt in option_fields(cls):
        if hasattr(args, dest(opt)):
            value = getattr(args, dest(opt))
            if opt.kind == "switch-off":
                value = not value
            values[field.name] = tuple(value) if isinstance(value, list) else value
    return values


def given_options(args: argparse.Namespace, cls) -> set[str]:
    """The fields of ``cls`` whose options the command line itself gave (``args.argv``), not
    a run file's or the package's defaults."""
    argv = getattr(args, "argv", [])
    return {field.name for field, opt in option_fields(cls)
            if any(a == f"--{opt.flag}" or a.startswith(f"--{opt.flag}=") for a in argv)}
