"""The command line generated from ``RunConfig``'s fields: every default is the field's (or, for
compare and study, their package settings files'), written once."""

import tomllib
from dataclasses import fields

from bench.cli.generated import run_values
from bench.cli.parser import COMPARE_OPTIONS, build_parser
from bench.matrix import RunConfig
from bench.matrix.config_files import COMPARE_SETTINGS, compare_settings
from bench.sequence.options import field_default, option_fields
from bench.study.run import STUDY_SETTINGS, StudyConfig


def test_run_has_an_option_for_every_field_with_the_field_default():
    parsed = run_values(build_parser().parse_args(["run"]), RunConfig)
    expected = {f.name: field_default(f) for f, _ in option_fields(RunConfig)}
    assert parsed == expected
    # every one but the record of the command and the parts (a run file's [[part]] tables)
    assert set(expected) == {f.name for f in fields(RunConfig)} - {"command", "parts"}


def test_the_default_run_is_the_dataclass_default():
    parsed = run_values(build_parser().parse_args(["run"]), RunConfig)
    assert RunConfig(**parsed).record() == RunConfig().record()


def test_compare_defaults_are_its_settings_file_then_the_fields():
    args = build_parser().parse_args(["compare"])
    settings = compare_settings()
    parsed = run_values(args, RunConfig)
    assert set(parsed) == set(COMPARE_OPTIONS)
    fields = dict((f.name, f) for f, _ in option_fields(RunConfig))
    for name, value in parsed.items():
        assert value == settings.get(name, field_default(fields[name])), name
    raw = tomllib.loads(COMPARE_SETTINGS.read_text())
    assert (args.dim, args.out) == (raw["dim"], raw["out"])
    assert "reports" not in raw and args.reports is None  # then OUT/report: the clone stays clean


def test_study_defaults_are_its_settings_file():
    args = build_parser().parse_args(["study"])
    raw = tomllib.loads(STUDY_SETTINGS.read_text())
    assert args.uniform_max_dofs == raw["uniform-max-dofs"] == StudyConfig().uniform_max_dofs
    assert args.adaptive_max_dofs == raw["adaptive-max-dofs"]
    assert tuple(args.study_file.settings.scenes) == tuple(raw["scenes"])
    assert (args.out, args.report, args.workers) == (raw["out"], raw["report"], raw["workers"])


def test_a_run_file_becomes_the_parser_defaults(tmp_path):
    path = tmp_path / "run.toml"
    path.write_text('scene = "hertz"\nmax-dofs = 777\ncold-start = true\n')
    from bench.cli.commands import run_file_defaults

    defaults = run_file_defaults(["run", "--config", str(path)])
    parsed = run_values(build_parser(defaults).parse_args(["run", "--max-levels", "3"]),
                        RunConfig)
    assert parsed["scenes"] == ("hertz",) and parsed["max_dofs"] == 777
    assert parsed["nested"] is False and parsed["max_levels"] == 3


def test_compare_reads_a_run_file_and_fills_what_it_leaves_out(tmp_path):
    from bench.cli.commands import compare_fields, compared_scenes, run_file_defaults
    from estimators import estimator_names

    path = tmp_path / "compare.toml"
    path.write_text('formulation = ["vi"]\nmax-dofs = 500\ndim = 2\nreports = "elsewhere"\n')
    argv = ["compare", "--config", str(path), "--crosscheck-dofs", "10"]
    defaults = run_file_defaults(argv)
    args = build_parser(defaults).parse_args(argv)
    args.file_fields = defaults["compare"]
    fields = compare_fields(args)
    assert fields["formulations"] == ("vi",) and fields["max_dofs"] == 500  # the file
    assert fields["crosscheck_dofs"] == 10 and args.reports == "elsewhere"  # option, file
    assert fields["solvers"] == compare_settings()["solvers"]  # the package's settings
    assert fields["scenes"] == compared_scenes(2)
    assert fields["estimators"] == estimator_names()  # every registered one
    RunConfig(**fields)  # a valid run
