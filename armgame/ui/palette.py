"""The game's looks: each palette's colours, and the palettes by name.

Here, below ``render`` and ``body``, which both draw with a palette: the arm's drawing (``body``) needs
the type and the renderer the palettes, and neither imports the other for them.
"""

from __future__ import annotations

from dataclasses import dataclass

RGB = tuple[int, int, int]


@dataclass(frozen=True)
class Palette:
    """Colours of one look. Text colours meet WCAG AA (4.5:1) on the surfaces they are drawn on."""

    name: str
    window: RGB  # behind the HUD
    scene: RGB  # the arm's plane
    workspace: RGB  # where the hand can reach
    edge: RGB  # faint outlines
    ink: RGB  # text
    faint: RGB  # help text
    link: RGB
    base: RGB  # the shoulder's fixed mount
    hand: RGB
    target: RGB
    flash: RGB
    trail: RGB
    warn: RGB  # the clock in its last 10 s
    bar_back: RGB
    muscles: tuple[RGB, RGB, RGB, RGB]
    panel: RGB
    skin: RGB  # the body's fill (its outline is ``link``)


PALETTES: dict[str, Palette] = {
    # Okabe & Ito (2008), "Color Universal Design": distinguishable with every common colour-vision
    # deficiency. Blue/orange for the shoulder pair, bluish green/reddish purple for the elbow pair.
    # Lines (trail, edge) are at least 3:1 on the scene and the workspace: a projector washes out the rest.
    "okabe-ito": Palette(
        "okabe-ito", window=(232, 235, 240), scene=(251, 251, 249), workspace=(240, 243, 248),
        edge=(120, 126, 138), ink=(22, 26, 34), faint=(70, 76, 88), link=(62, 68, 82), base=(120, 126, 138),
        hand=(15, 15, 20), target=(213, 94, 0), flash=(240, 228, 66), trail=(30, 136, 200), warn=(176, 58, 0),
        bar_back=(214, 219, 227), muscles=((0, 114, 178), (230, 159, 0), (0, 158, 115), (204, 121, 167)),
        panel=(255, 255, 255), skin=(236, 226, 214),
    ),
    # The 2012 game's colours (red target, black hand), on the same layout.
    "classic": Palette(
        "classic", window=(235, 235, 235), scene=(255, 255, 255), workspace=(246, 246, 246),
        edge=(125, 125, 125), ink=(20, 20, 20), faint=(80, 80, 80), link=(70, 70, 80), base=(120, 120, 120),
        hand=(0, 0, 0), target=(220, 30, 30), flash=(255, 200, 0), trail=(50, 100, 190), warn=(180, 0, 0),
        bar_back=(225, 225, 230), muscles=((40, 110, 200), (40, 160, 120), (200, 120, 30), (150, 60, 170)),
        panel=(255, 255, 255), skin=(238, 232, 226),
    ),
    # For a large, bright room: black on white, every colour at least 4.5:1 on white, nothing pale.
    "high-contrast": Palette(
        "high-contrast", window=(255, 255, 255), scene=(255, 255, 255), workspace=(236, 236, 236),
        edge=(0, 0, 0), ink=(0, 0, 0), faint=(0, 0, 0), link=(0, 0, 0), base=(0, 0, 0),
        hand=(0, 0, 0), target=(200, 0, 0), flash=(255, 210, 0), trail=(90, 90, 90), warn=(170, 0, 0),
        bar_back=(200, 200, 200), muscles=((0, 80, 220), (180, 90, 0), (0, 120, 60), (160, 0, 160)),
        panel=(255, 255, 255), skin=(225, 225, 225),
    ),
}
