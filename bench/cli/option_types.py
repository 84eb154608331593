"""Validating option types of the command line: a bad value is refused naming the option, the
value and what is allowed."""

from __future__ import annotations

import argparse
import math
import sys

from bench.matrix.distributed import SchedulerError, scheduler_endpoint
from bench.matrix.spec import parse_item
from bench.perf.sequence import SEQUENCES
from formulations.cells import cell_names
from formulations.elasticity import ORDERS


def name_list(kind: str, valid: list[str], plural: str | None = None, sweep: bool = False,
              broken: dict[str, str] | None = None):
    """A comma-separated list of names from ``valid`` (``kind``: what one name is); a name
    given twice is kept once, with a note on standard error. With ``sweep`` an item may carry
    parameters, ``name:key=v1|v2:other=w`` (``bench.matrix.spec.parse_item``); ``broken``:
    why a name that failed to load is left out, said when it is asked for."""
    def parse(text: str) -> list[str]:
        names = [name.strip() for name in text.split(",") if name.strip()]
        if sweep:
            for item in names:
                try:
                    parse_item(item, kind)
                except ValueError as error:
                    raise argparse.ArgumentTypeError(str(error)) from None
        unknown = [name for name in names if name.split(":")[0] not in valid]
        left_out = [f"{kind} {name!r} is broken: {(broken or {})[name]}"
                    for name in unknown if name in (broken or {})]
        if left_out:
            raise argparse.ArgumentTypeError("; ".join(left_out))
        if not names or unknown:
            raise argparse.ArgumentTypeError(
                f"unknown {kind} {', '.join(map(repr, unknown)) or repr(text)}; "
                f"valid {plural or kind + 's'}: {', '.join(valid)}")
        once = list(dict.fromkeys(names))
        for name in {n for n in names if names.count(n) > 1}:
            print(f"note: {kind} {name!r} given {names.count(name)} times; running it once",
                  file=sys.stderr)
        return once
    return parse


def cell_list(text: str) -> list[str]:
    """A comma-separated list of cell shapes (``formulations.cells``)."""
    return name_list("cell", cell_names())(text)


def order_list(text: str) -> list[int]:
    """A comma-separated list of polynomial orders from ``ORDERS``."""
    items = [item.strip() for item in text.split(",") if item.strip()]
    values = [integer_value(item) for item in items]
    if not items or any(v not in ORDERS for v in values):
        raise argparse.ArgumentTypeError(
            f"order={text!r} is not a comma-separated list of orders from "
            f"{', '.join(map(str, ORDERS))}")
    once = list(dict.fromkeys(values))
    if len(once) < len(values):
        print(f"note: order given more than once in {text!r}; running each once",
              file=sys.stderr)
    return once


def integer_value(text: str) -> int | None:
    """``text`` as an int, also when written as a float with an integer value ("1e3", "2.0");
    None when it is not an integer."""
    try:
        return int(text)
    except ValueError:
        pass
    try:
        value = float(text)
    except ValueError:
        return None
    return int(value) if value.is_integer() else None


def bounded_int(name: str, minimum: int, allowed: str):
    """An int option >= ``minimum``, refused as "name='text' is not <allowed>"."""
    def parse(text: str) -> int:
        value = integer_value(text)
        if value is None:
            value = minimum - 1
        if value < minimum:
            raise argparse.ArgumentTypeError(f"{name}={text!r} is not {allowed}")
        return value
    return parse


def positive_int(name: str):
    return bounded_int(name, 1, "a positive integer")


def sequence_budgets(text: str) -> list[int]:
    """One positive DOF budget per sequence of ``SEQUENCES``, comma-separated."""
    parse = positive_int("sequence_max_dofs")
    items = [item.strip() for item in text.split(",")]
    if len(items) != len(SEQUENCES):
        raise argparse.ArgumentTypeError(
            f"sequence_max_dofs={text!r} is not {len(SEQUENCES)} comma-separated budgets "
            f"(for {', '.join(s for s, _ in SEQUENCES)})")
    return [parse(item) for item in items]


def non_negative_int(name: str):
    return bounded_int(name, 0, "an integer >= 0")


def gib(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not (value > 0 and value < float("inf")):
        raise argparse.ArgumentTypeError(f"max_memory={text!r} is not a number of GiB > 0")
    return value


def positive_float(name: str):
    """A finite number > 0, named ``name`` in the error."""
    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            value = float("nan")
        if not (math.isfinite(value) and value > 0):
            raise argparse.ArgumentTypeError(f"{name}={text!r} is not a number > 0")
        return value

    return parse


def theta_value(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not 0.0 < value <= 1.0:
        raise argparse.ArgumentTypeError(f"theta={text!r} is not a number in (0, 1]")
    return value


def scheduler_address(text: str) -> str:
    """A Dask scheduler address, SCHEME://HOST:PORT (whether one answers there is checked
    when the run starts, with a bounded wait)."""
    try:
        scheduler_endpoint(text)
    except SchedulerError as error:
        raise argparse.ArgumentTypeError(str(error)) from None
    return text
