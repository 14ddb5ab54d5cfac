"""The adaptation lab: a centre-out reaching task on the game's session, its perturbations, bots and measures.

Pure (no pygame): ``protocol`` (blocks, presets, TOML files), ``perturbations`` (force fields and
visual transforms per trial), ``session`` (``LabSession``, the task on ``GameSession``), ``bots``
(the adapting bot), ``record`` (the task section of a lab replay), ``runs`` (headless runs and
their outputs), and the metrics helper's ``metrics``, ``learner`` and ``figures``. The window is
``armgame.ui.lab_window``; the commands are ``armgame lab`` and ``armgame analyze``.
"""
