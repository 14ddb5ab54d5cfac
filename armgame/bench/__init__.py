"""Speed against error: the work-precision benchmark behind ``armgame bench`` and the defaults.

``measure`` runs armgame's fixed-step schemes, ``peers`` the same cases through the tutorial's
method, scipy and MuJoCo, ``figures`` draws the plots. Bench code sits above ``physics`` and
``scenes`` and imports from them, never the other way round.
"""
