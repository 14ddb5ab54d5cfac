"""The dynamics lab: adaptation experiments measured per reach. Pure Python and numpy; no pygame.

The lab owns the experiment protocols (blocks of baseline, exposure and washout trials, catch
trials, presets and teachers' protocol files), the centre-out task that runs them on the game's
fixed-step session, the per-reach metrics computed from re-simulated hand paths (``metrics``),
the trial-by-trial state-space learner that drives the adapting bot (``learner``) and the
figures a teacher shows (``figures``, which imports matplotlib only when a figure is drawn).
The window that plays a protocol lives in ``armgame.ui``; the commands in ``armgame.commands``.
"""
