"""bench: the harness that runs formulations and estimators over scenes and judges them.

Sub-packages by role, each importing only those before it in this order:

* ``measure``: contact zone, solution differences, discretisation errors of one solution;
* ``sequence``: one refinement sequence (solve -> estimate -> mark -> refine), result rows;
* ``truth``: what errors are measured against (exact solutions, cached overkill references);
* ``matrix``: the cross product of a run, its result store and rates (``RunConfig``, ``run``);
* ``hard``: the hard cases and their verdicts;
* ``verify``: the gates of ``expected.toml``;
* ``report``: Markdown and HTML report with figures;
* ``perf``: the scaling table;

and ``cli`` on top (``python -m bench``).
"""
