"""A sequence's task: the combination is warmed up once per process, untimed and unrecorded."""

import bench.matrix.task as task
from bench.matrix import RunConfig, run


def test_each_combination_is_warmed_up_once_and_records_nothing(tmp_path, monkeypatch):
    calls = []

    def counting(*args, **kwargs):
        calls.append(args[4].max_levels)  # the LoopConfig
        return real(*args, **kwargs)

    real = task.run_sequence
    monkeypatch.setattr(task, "run_sequence", counting)
    monkeypatch.setattr(task, "_warmed", set())
    rows = run(RunConfig(scenes=("free-boundary",), formulations=("vi",),
                         solvers=("active-set",), estimators=("residual",),
                         strategies=("uniform", "adaptive"), max_dofs=300,
                         out=str(tmp_path))).rows
    # one warm-up of WARM_UP_LEVELS levels, then the two timed sequences
    assert calls[0] == task.WARM_UP_LEVELS and len(calls) == 3
    assert calls[1] > task.WARM_UP_LEVELS and calls[2] > task.WARM_UP_LEVELS
    # only the timed sequences' levels are rows: each starts at level 0 once
    assert sorted(r.strategy for r in rows if r.level == 0) == ["adaptive", "uniform"]
