"""What every figure armgame writes must satisfy to be shown on a slide (used by the figure tests)."""

import itertools

from armgame.plotstyle import MIN_FONT_PT, SLIDE_DPI, smallest_font_pt


def _overlap(a, b) -> bool:
    return a.x0 < b.x1 and b.x0 < a.x1 and a.y0 < b.y1 and b.y0 < a.y1


def assert_reads_on_a_slide(fig) -> None:
    """1920 x 1080 px; no text under MIN_FONT_PT; legends off every panel's data area; no two texts
    within a panel (labels, printed values, slope labels) on top of each other; nothing off the page."""
    width, height = fig.get_size_inches() * SLIDE_DPI
    assert (round(width), round(height)) == (1920, 1080)
    assert smallest_font_pt(fig) >= MIN_FONT_PT
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(fig)
    fig.draw_without_rendering()  # lays the figure out as savefig did (without painting the pixels again)
    renderer = canvas.get_renderer()
    page = fig.bbox
    panels = [ax for ax in fig.get_axes() if ax.axison]
    legends = [ax.get_legend() for ax in fig.get_axes()] + list(fig.legends)
    for ax in fig.get_axes():
        assert ax.get_window_extent(renderer).x1 <= page.x1 + 1
    for legend in filter(None, legends):
        box = legend.get_window_extent(renderer)
        assert page.x0 - 1 <= box.x0 and box.x1 <= page.x1 + 1 and page.y0 - 1 <= box.y0 and box.y1 <= page.y1 + 1
        for ax in panels:
            assert not _overlap(box, ax.get_window_extent(renderer)), f"legend on the data of {ax.get_title()!r}"
    for ax in panels:
        texts = [t for t in ax.texts if t.get_visible() and t.get_text().strip()]
        for a, b in itertools.combinations(texts, 2):
            assert not _overlap(a.get_window_extent(renderer), b.get_window_extent(renderer)), (
                f"{a.get_text()!r} overlaps {b.get_text()!r}")
    for text in fig.findobj(lambda a: hasattr(a, "get_text") and a.get_visible()):
        if text.get_text().strip() and text.get_figure() is fig and not text.get_clip_on():
            box = text.get_window_extent(renderer)
            assert page.x0 - 2 <= box.x0 and box.x1 <= page.x1 + 2, f"{text.get_text()!r} runs off the page"
