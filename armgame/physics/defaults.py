"""The integrators and steps armgame uses by default, chosen from ``armgame bench`` data.

The README's "Performance" section has the table these come from and the reasoning. In short:

* the game's step and integrator are the cheapest (time per simulated second, one arm)
  whose hand error stays below 0.1 mm over the first 2 s of the game case and whose
  energy holds within 1e-6 (relative) over 60 s of the passive case, without blowing up
  on any hard case;
* ``simulate``'s are the cheapest (on the passive case) that keep the hand within 1 um of the
  reference over 2 s and the energy within 1e-6 over 60 s on every hard case: offline runs are
  for looking at, energy plots included, so they buy accuracy the game does not need.

Re-run ``armgame bench`` after changing the dynamics or the integrators; its output names
the choice the data make, which should match these.
"""

#: Criteria the defaults are chosen by (``armgame.bench.measure.choose`` applies them).
GAME_MAX_HAND_ERROR = 1e-4  # m, over the first 2 s of the game case
GAME_MAX_ENERGY_DRIFT = 1e-6  # relative, over 60 s of the passive case
SIMULATE_MAX_HAND_ERROR = 1e-6  # m, over the first 2 s of every hard case
SIMULATE_MAX_ENERGY_DRIFT = 1e-6  # relative, over 60 s of every hard case

GAME_INTEGRATOR = "rk4"
GAME_DT = 1.0 / 250.0
SIMULATE_INTEGRATOR = "rk4"
SIMULATE_DT = 1.0 / 4000.0

#: A joint faster than this has blown up: no scene, game or demo comes near it (the propeller peaks
#: near 70 rad/s, ``simulate --initial`` allows 628). The benchmark and ``simulate`` judge by it.
BLOWUP_SPEED = 1e4  # rad/s
