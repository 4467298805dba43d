"""Adaptive module activation (paper, section "Adaptive Module Activation Experiment"; SPEC 7):
reach a virtual point with one module, switching on its neighbours only while they lower the
error, and measure the actuation effort this saves against all modules on.

- ``procedure``: the staged procedure as a state machine, independent of physics.
- ``experiment``: drives it in physics, one continuous reach episode per target, and the
  all-modules-on comparison.
- ``report``: the ``adaptive`` section of the result record, and the printed table.
- ``plot``: the figure (error per stage over targets, paths traced), from the record alone.
- ``runner``: ``run``, the experiment for ``softbench run --adaptive``: builds the agent, reaches
  the targets, returns the record's section.

``softbench run --task reach --agent smpl --adaptive [--targets N] [--module K]`` calls
``runner.run``.
Every learned agent can take part: inactive modules get zero actuation (``LearnedAgent``'s
``active_modules``); SMPL's inactive columns keep observing, and a centralised baseline still
computes every output, masked the same way.
"""

DEFAULT_TARGETS = 20  # Virtual targets of ``softbench run --adaptive``.
MAX_TARGETS = 10_000  # Checked before any work: the record holds a section per target.
