"""The dynamics lab: adaptation experiments measured per reach. Pure Python and numpy; no pygame.

``protocol`` (a protocol: blocks of baseline, exposure and washout trials, catch and channel
trials, checked as it is built), ``perturbations`` (one record per kind of force field or visual
transform: its parameters, its words in a file, its loads and display), ``presets`` (the named
protocols), ``protocol_file`` (teachers' TOML files and a replay's protocol, read and written),
``session`` (``LabSession``: the centre-out task on the game's fixed-step session), ``bots``
(the game's bots in the lab, and the adapting bot), ``record`` (the task section of a lab
replay), ``analysis`` (rows and figures of a run), ``metrics`` (per-reach metrics from hand
paths), ``learner`` (the trial-by-trial state-space learner) and ``figures`` (matplotlib, imported
only when a figure is drawn). The window is ``armgame.ui.lab_window``; the commands are
``armgame lab`` and ``armgame analyze``.
"""
