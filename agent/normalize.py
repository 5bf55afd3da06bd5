"""Deterministic clean-up of a spoken or typed task before it reaches the LLM.

A 270M model copies numbers well but cannot do arithmetic, so everything the
model would otherwise have to compute is done here: number words become
digits, units become the profile's units (metres and radians), ASR homophones
in numeric context become digits, words a recognizer split in two ("for ty",
"a round") are joined, and fillers go. Object words are kept.

The output format is a contract with the adapter's training data, which is
normalized by this same function: lowercase words separated by single
spaces, clause commas written as ", ", numbers in canonical RSL spelling
(at most 4 decimals), and every converted length or angle followed by `m`
or `rad`. Improve coverage freely; do not change that format.
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence

from agent.corrections import MARKERS
from rsl.plan import format_number

_TOKEN = re.compile(r"\d*\.\d+|\d+|[a-z]+(?:'[a-z]+)?|°|,|[.!?;:]")

ONES = {
    "zero": 0, "nought": 0, "naught": 0, "oh": 0, "one": 1, "two": 2, "three": 3, "four": 4, "five": 5,
    "six": 6, "seven": 7, "eight": 8, "nine": 9, "ten": 10, "eleven": 11, "twelve": 12, "thirteen": 13, "fourteen": 14,
    "fifteen": 15, "sixteen": 16, "seventeen": 17, "eighteen": 18, "nineteen": 19,
}
_TENS = {"twenty": 20, "thirty": 30, "forty": 40, "fifty": 50, "sixty": 60, "seventy": 70,
         "eighty": 80, "ninety": 90}
_DIGIT_WORDS = {**{w: v for w, v in ONES.items() if v < 10}, "o": 0}
_FRACTIONS = {"half": 0.5, "quarter": 0.25, "third": 1 / 3}
# The parts a whole is cut into: "a third", "three quarters", "two fifths".
_DENOMINATORS = {
    **dict.fromkeys(("half", "halves"), 2), **dict.fromkeys(("third", "thirds"), 3),
    **dict.fromkeys(("quarter", "quarters"), 4), **dict.fromkeys(("fifth", "fifths"), 5),
    **dict.fromkeys(("sixth", "sixths"), 6), **dict.fromkeys(("eighth", "eighths"), 8),
    **dict.fromkeys(("tenth", "tenths"), 10),
}

# Words an ASR writes for a number word; only read as numbers when a unit or
# `times` follows, so "go to the door" and "look for the cup" are untouched.
NUMBER_HOMOPHONES = {"to": 2, "too": 2, "for": 4, "fore": 4, "won": 1, "ate": 8, "tree": 3, "free": 3}

_LENGTHS = {
    **dict.fromkeys(("m", "meter", "meters", "metre", "metres", "mtr", "mtrs"), 1.0),
    **dict.fromkeys(("cm", "centimeter", "centimeters", "centimetre", "centimetres", "cms"), 0.01),
    **dict.fromkeys(("mm", "millimeter", "millimeters", "millimetre", "millimetres"), 0.001),
    **dict.fromkeys(("ft", "foot", "feet"), 0.3048),
    **dict.fromkeys(("inch", "inches"), 0.0254),
    **dict.fromkeys(("yard", "yards", "yd"), 0.9144),
    **dict.fromkeys(("km", "kilometer", "kilometers", "kilometre", "kilometres"), 1000.0),
}
# A length's factor -> the factor of the unit a bare number right after it is in: centimetres, inches.
_UNSAID_SMALLER = {1.0: 0.01, 0.3048: 0.0254}
_ANGLES = {
    **dict.fromkeys(("degree", "degrees", "deg", "degs", "°"), math.pi / 180),
    **dict.fromkeys(("rad", "rads", "radian", "radians"), 1.0),
}
# What a fraction of a turn is a fraction of: "a third of a turn", "half a circle".
_ONE_REVOLUTION = ("turn", "circle", "rotation", "revolution")
# Whole turns: "two full turns", "3 circles". A bare "a turn" stays a verb.
_REVOLUTIONS = {"turn", "turns", "circle", "circles", "rotation", "rotations", "revolution",
                "revolutions", "spin", "spins", "lap", "laps"}

# The ways a turn goes. A bare number after one that is too large to be radians of a turn
# ("turn left 90") can only be degrees: left as it is, the model copies it into a 90 rad turn.
_TURN_WAYS = frozenset({"left", "right", "clockwise", "counterclockwise", "anticlockwise", "around"})
# "do a 180": an article before a bare number of degrees names a turn of that size.
_ARTICLES = frozenset({"a", "an"})
_LARGEST_BARE_DEGREES = 360

_FILLERS: tuple[tuple[str, ...], ...] = tuple(
    tuple(p.split())
    for p in sorted(
        [
            "uh", "uhm", "uhh", "um", "umm", "erm", "er", "ah", "ahh", "hmm", "mm", "please", "kindly",
            "could you", "can you", "would you", "will you", "could you please", "would you please",
            "i want you to", "i need you to", "i'd like you to", "i would like you to", "you know",
            "go ahead and", "hey robot", "ok robot", "okay robot", "okay", "ok", "alright", "just",
            "for me", "robot could you",
        ],
        key=lambda p: -len(p.split()),
    )
)


def normalize_task(text: str) -> str:
    """Normalize one task; see the module docstring for the output format."""
    tokens = _tokenize(text)
    tokens = _drop_fillers(tokens)
    tokens = _hear_to(tokens)
    tokens = _join_split_numbers(tokens)
    tokens = _join_split_words(tokens)
    tokens = _carry_corrected_units(tokens)
    tokens = _carry_correcting_units(tokens)
    tokens = _convert_numbers(tokens)
    return _render(tokens)


def _tokenize(text: str) -> list[str]:
    lowered = text.lower().replace("’", "'")
    # "twenty-five", "x-axis": a hyphen between words is a space; a minus
    # before a digit is kept as a word so coordinates stay signed.
    lowered = re.sub(r"(?<=[a-z])-(?=[a-z])", " ", lowered)
    lowered = re.sub(r"(?<![\w.])-(?=\.?\d)", " minus ", lowered)
    tokens = []
    for raw in _TOKEN.findall(lowered):
        tokens.append("," if raw in ".!?;:" else raw)
    return tokens


def _drop_fillers(tokens: list[str]) -> list[str]:
    out: list[str] = []
    i = 0
    while i < len(tokens):
        for phrase in _FILLERS:
            end = i + len(phrase)
            if tuple(tokens[i:end]) == phrase and not _asks_whether(phrase, tokens[end:end + 1]):
                i = end
                break
        else:
            out.append(tokens[i])
            i += 1
    return out


def _asks_whether(phrase: tuple[str, ...], following: list[str]) -> bool:
    """Whether a polite "can you" is a question instead: "can you see the cup?" asks whether the robot sees
    it, and with "can you" dropped it would read as an order to look."""
    return phrase[-1] == "you" and following == ["see"]


# A number is never followed by a determiner, so "go too the fridge" is "go to the fridge".
_TO_HEARD_AS = frozenset({"two", "too"})
_DETERMINERS = frozenset({"the", "your", "my", "its", "his", "her", "their", "our"})


def _hear_to(tokens: list[str]) -> list[str]:
    return ["to" if t in _TO_HEARD_AS and tokens[i + 1:i + 2] and tokens[i + 1] in _DETERMINERS else t
            for i, t in enumerate(tokens)]


# A recognizer that splits a number word in two ("for ty five", "six teen"): the halves are no words.
_NUMBER_ENDINGS = ("ty", "teen")
_FOUR_HEARD_AS = frozenset({"for", "fore", "four"})


def _join_split_numbers(tokens: list[str]) -> list[str]:
    out: list[str] = []
    for token in tokens:
        if token in _NUMBER_ENDINGS and out:
            joined = out[-1] + token
            if out[-1] in _FOUR_HEARD_AS:
                joined = "forty" if token == "ty" else "fourteen"
            if joined in _TENS or joined in ONES:
                out[-1] = joined
                continue
        out.append(token)
    return out


# Words a recognizer splits in two ("turn a round", "to wards"). "a round" is also an article and an
# adjective ("grab a round box"), so it is joined only where no noun follows; "a head" is the robot's head
# misheard ("pan a head left"), never joined. A skill's own words are the profile's to name, not this table's.
_SPLIT_WORDS = {("to", "wards"): "towards"}
_SPLIT_BEFORE_NO_NOUN = {("a", "round"): "around"}
_NO_NOUN = frozenset({",", "to", "and", "then", "the", "your", "please", "again", "once", "twice", "left", "right",
                      "now"})


def _join_split_words(tokens: list[str]) -> list[str]:
    out: list[str] = []
    i = 0
    while i < len(tokens):
        pair = (tokens[i], tokens[i + 1] if i + 1 < len(tokens) else "")
        after = tokens[i + 2] if i + 2 < len(tokens) else ","
        joined = _SPLIT_WORDS.get(pair)
        if pair in _SPLIT_BEFORE_NO_NOUN and (after in _NO_NOUN or _parse_number(tokens, i + 2) is not None):
            joined = _SPLIT_BEFORE_NO_NOUN[pair]
        if joined is not None:
            out.append(joined)
            i += 2
        else:
            out.append(tokens[i])
            i += 1
    return out


_MARKER_WORDS = tuple(tuple(m.split()) for m in MARKERS)


def _carry_corrected_units(tokens: list[str]) -> list[str]:
    """A bare number that corrects an amount takes the amount's unit: "30 degrees, no, 60" is 60 degrees.

    Left bare, the number would reach the model with no unit, and the
    model copies numbers: it planned a 60 rad turn.
    """
    out = list(tokens)
    for at in range(len(out) - 1, 0, -1):
        unit = _unit_before(out, at)
        if unit is None:
            continue
        # Commas may be several: an ellipsis ("30 degrees... no, 60") is read as commas, and so is a
        # filler's ("30 degrees, uh, no, 60") once the filler is dropped.
        j = _past_markers(out, at)
        parsed = None if j is None else _parse_number(out, j)
        if parsed is None:
            continue
        end = parsed[1]
        if end < len(out) and (out[end] == "times" or _unit_at(out, end) or _revolutions_at(out, end)):
            continue
        out.insert(end, unit)
    return out


# Words that may come between an amount and the marker that corrects it: the way it goes ("45 degrees to the
# left, make that 60").
_WAY_WORDS = _TURN_WAYS | {"to", "the", "your", "my"}
_WAY_WORDS_BETWEEN = 3


def _unit_before(tokens: Sequence[str], at: int) -> str | None:
    """The unit of the amount said last before tokens[at], with at most a few words of its way between."""
    for k in range(at - 1, max(-1, at - 2 - _WAY_WORDS_BETWEEN), -1):
        if tokens[k] in _LENGTHS or tokens[k] in _ANGLES:
            return tokens[k]
        if tokens[k] not in _WAY_WORDS:
            return None
    return None


def _carry_correcting_units(tokens: list[str]) -> list[str]:
    """A bare number corrected by an amount takes its unit: "forward three, sorry, four metres" is 3 m first.

    Left bare, the number taken back reads as another amount, and the
    checks would doubt a plan that rightly drops it.
    """
    out = list(tokens)
    for at in range(len(out) - 1, -1, -1):
        if at and _parse_number(out, at - 1) is not None:
            continue
        parsed = _parse_number(out, at)
        if parsed is None:
            continue
        end = parsed[1]
        j = _past_markers(out, end)
        corrected = None if j is None else _parse_number(out, j)
        if corrected is None or (unit := _unit_at(out, corrected[1])) is None:
            continue
        out[end:end] = out[corrected[1]:unit[2]]
    return out


def _past_markers(tokens: Sequence[str], i: int) -> int | None:
    """Where the words after the correction markers at tokens[i] begin; None if none is there.

    Markers may come in a run ("90 degrees, no, make that 45"), and
    commas around them may be several.
    """
    j = _past_commas(tokens, i)
    found = False
    while (marker := next((m for m in _MARKER_WORDS if tuple(tokens[j:j + len(m)]) == m), None)) is not None:
        j, found = _past_commas(tokens, j + len(marker)), True
    return j if found else None


def _past_commas(tokens: Sequence[str], i: int) -> int:
    while tokens[i:i + 1] == [","]:
        i += 1
    return i


def _is_number_token(token: str) -> bool:
    return bool(re.fullmatch(r"\d*\.\d+|\d+", token))


def _parse_integer_words(tokens: Sequence[str], i: int) -> tuple[float, int] | None:
    """`twenty five`, `one hundred and twenty`, `three sixty`, `seven`: value and next index."""
    value = 0
    last = ""  # the kind of the previous word: ones, tens, hundred, thousand, and
    j = i
    while j < len(tokens):
        word = tokens[j]
        if word in ("a", "an") and j == i and tokens[j + 1:j + 2] in (["hundred"], ["thousand"]):
            # "a hundred and eighty degrees" is one number; read from "hundred" on, it would be eighty.
            value, last = 1, "ones"
        elif word in ONES and word != "oh" and (
                last in ("", "hundred", "thousand", "and") or (last == "tens" and ONES[word] < 10)):
            value, last = value + ONES[word], "ones"
        elif word in _TENS and last in ("", "hundred", "thousand", "and"):
            value, last = value + _TENS[word], "tens"
        elif word in _TENS and last == "ones" and j == i + 1 and value < 10:
            # Hundreds said as two numbers, as people say angles: "one eighty", "three sixty".
            value, last = value * 100 + _TENS[word], "tens"
        elif word == "hundred" and last in ("ones", "tens") and value % 1000 < 100:
            # Only what was said after the thousands counts hundreds: "a thousand two hundred".
            thousands = value - value % 1000
            value, last = thousands + value % 1000 * 100, "hundred"
        elif word == "thousand" and last in ("ones", "tens", "hundred") and value < 1000:
            value, last = value * 1000, "thousand"
        elif (word == "and" and last in ("hundred", "thousand") and j + 1 < len(tokens)
              and (tokens[j + 1] in ONES or tokens[j + 1] in _TENS)):
            last = "and"
        else:
            break
        j += 1
    if last in ("", "and"):
        return None
    return float(value), j


def _parse_number(tokens: Sequence[str], i: int) -> tuple[float, int] | None:
    """A number starting at tokens[i], in digits or words, with its fractions."""
    sign = 1.0
    j = i
    if j < len(tokens) and tokens[j] in ("minus", "negative") and j + 1 < len(tokens):
        sign, j = -1.0, j + 1
    value: float
    if j < len(tokens) and _is_number_token(tokens[j]):
        value, j = float(tokens[j]), j + 1
    elif (parsed := _parse_integer_words(tokens, j)) is not None:
        value, j = parsed
    elif j + 1 < len(tokens) and tokens[j] == "point" and tokens[j + 1] in _DIGIT_WORDS:
        value = 0.0
    else:
        return None
    if j + 1 < len(tokens) and tokens[j] == "point" and tokens[j + 1] in _DIGIT_WORDS:
        digits = ""
        j += 1
        while j < len(tokens) and tokens[j] in _DIGIT_WORDS:
            digits += str(_DIGIT_WORDS[tokens[j]])
            j += 1
        value += float("0." + digits)
    if tokens[j:j + 3] in (["and", "a", "half"], ["and", "a", "quarter"]):
        value += _FRACTIONS[tokens[j + 2]]
        j += 3
    return sign * value, j


def _fraction_phrase(tokens: Sequence[str], i: int) -> tuple[float, int] | None:
    """`half a`, `a half`, `a quarter of a`, `a`/`an` before a unit: value and next index."""
    rest = tokens[i:i + 4]
    for phrase, value in (
        (["half", "of", "a"], 0.5), (["half", "a"], 0.5), (["half", "an"], 0.5),
        (["a", "quarter", "of", "a"], 0.25), (["quarter", "of", "a"], 0.25), (["a", "quarter"], 0.25),
        (["a", "half"], 0.5), (["half"], 0.5), (["quarter"], 0.25),
        (["a", "couple", "of"], 2.0), (["a", "couple"], 2.0),
        (["a"], 1.0), (["an"], 1.0), (["one"], 1.0),
    ):
        if rest[:len(phrase)] == phrase:
            return value, i + len(phrase)
    return None


def _unit_at(tokens: Sequence[str], j: int) -> tuple[str, float, int] | None:
    """A unit word at tokens[j]: (profile unit, factor, next index)."""
    if j >= len(tokens):
        return None
    word = tokens[j]
    if word in _LENGTHS:
        return "m", _LENGTHS[word], j + 1
    if word in _ANGLES:
        return "rad", _ANGLES[word], j + 1
    if word in ("full", "complete", "whole") and j + 1 < len(tokens) and tokens[j + 1] in _REVOLUTIONS:
        return "rad", 2 * math.pi, j + 2
    return None


def _revolutions_at(tokens: Sequence[str], j: int) -> int | None:
    if j < len(tokens) and tokens[j] in _REVOLUTIONS and tokens[j].endswith("s"):
        return j + 1
    return None


def _with_unit(tokens: Sequence[str], value: float, j: int, *, explicit: bool) -> tuple[str, int] | None:
    """`value` followed by a unit at tokens[j], rendered as `N m` / `N rad`."""
    unit = _unit_at(tokens, j)
    if unit is None and explicit and (end := _revolutions_at(tokens, j)) is not None:
        unit = ("rad", 2 * math.pi, end)
    if unit is None:
        return None
    name, factor, end = unit
    # "two meters and a half", "a meter and a half"
    if tokens[end:end + 3] == ["and", "a", "half"]:
        value, end = value + 0.5, end + 3
    total = value * factor
    if name == "m":
        # "two feet six inches", "a metre and twenty centimetres": one length said in two units.
        # Left as two lengths, the model drives the first and drops or adds the second.
        total, end = _smaller_length_after(tokens, end, factor, total)
    return f"{format_number(total)} {name}", end


def _smaller_length_after(tokens: Sequence[str], end: int, factor: float, total: float) -> tuple[float, int]:
    """`total` with a length in a smaller unit that follows at tokens[end] added, and the index after it."""
    start = end + 1 if tokens[end:end + 1] == ["and"] else end
    parsed = _parse_number(tokens, start)
    if parsed is None or parsed[0] <= 0:
        return total, end
    value, j = parsed
    if j < len(tokens) and tokens[j] in _LENGTHS:
        if _LENGTHS[tokens[j]] >= factor:
            return total, end
        return total + value * _LENGTHS[tokens[j]], j + 1
    # "a metre fifty", "two foot six": the smaller unit goes unsaid, as people say heights.
    implied = _UNSAID_SMALLER.get(factor)
    if (implied is None or start != end or value != int(value) or value * implied >= factor
            or _unit_at(tokens, j) is not None or tokens[j:j + 1] in (["times"], ["more"], ["of"])
            or _coordinates_at(tokens, start) is not None):
        return total, end
    return total + value * implied, j


def _convert_numbers(tokens: list[str]) -> list[str]:
    out: list[str] = []
    i = 0
    while i < len(tokens):
        token = tokens[i]
        # "the point 2, 5" and "to point 3 comma minus 2" name a place; "point 2" alone is a decimal.
        place = token == "point" and (out[-1:] in (["the"], ["a"]) or _coordinates_at(tokens, i + 1) is not None)
        converted = None if place else _convert_at(tokens, i)
        if converted is not None and converted[1] > i:
            text, i = converted
            out.append(text)
            continue
        if token in ("twice", "thrice"):
            out.append("2 times" if token == "twice" else "3 times")
        elif token == "comma" and out and _is_number_token(out[-1]) and (
                _parse_number(tokens, i + 1) is not None or _in_point(tokens, i + 1)):
            # A comma said between two numbers, as a recognizer writes coordinates.
            out.append(",")
        else:
            out.append(token)
        i += 1
    return out


def _coordinates_at(tokens: Sequence[str], i: int) -> int | None:
    """Where two numbers said as a point ("3 comma minus 2", "two, five") end, or None."""
    first = _parse_number(tokens, i)
    if first is None or first[1] >= len(tokens) or tokens[first[1]] not in (",", "comma", "and"):
        return None
    second = _parse_number(tokens, first[1] + 1)
    return None if second is None else second[1]


# The words that put a point right before its coordinates ("the point for comma one", "at too, for").
_POINT_WORDS = frozenset({"point", "at", "to", "coordinates", "position", "location"})
# What may follow a point's second coordinate: the end of its clause.
_CLAUSE_ENDS = frozenset({",", ".", "and", "then", "please"})


def _in_point(tokens: Sequence[str], i: int) -> bool:
    """Whether tokens[i] is a homophone of a number and one of two numbers said as a point right after a
    word that names one: "the point for comma one", "go to two, for". A recognizer spells a number that way
    wherever one is said, not only before a unit; "look for, 2 cups" and "go to 1, for the cup" stay words."""
    def number_at(k: int) -> bool:
        return 0 <= k < len(tokens) and (tokens[k] in NUMBER_HOMOPHONES or _parse_number(tokens, k) is not None)

    if i >= len(tokens) or tokens[i] not in NUMBER_HOMOPHONES:
        return False
    comma = (",", "comma")
    first = (i >= 1 and tokens[i - 1] in _POINT_WORDS and i + 2 < len(tokens) and tokens[i + 1] in comma
             and number_at(i + 2))
    second = (i >= 3 and tokens[i - 1] in comma and number_at(i - 2) and tokens[i - 3] in _POINT_WORDS
              and (i + 1 == len(tokens) or tokens[i + 1] in _CLAUSE_ENDS))
    return first or second


def _u_turn_at(tokens: Sequence[str], i: int) -> int | None:
    """The index after a U-turn ("a u turn", "uturn") that starts at tokens[i]: half a revolution."""
    j = i + 1 if tokens[i] in ("a", "an") else i
    if tokens[j:j + 2] == ["u", "turn"]:
        return j + 2
    if tokens[j:j + 1] == ["uturn"]:
        return j + 1
    return None


def _convert_at(tokens: list[str], i: int) -> tuple[str, int] | None:
    if (end := _u_turn_at(tokens, i)) is not None:
        # The verb stays: "make a u-turn" asks the robot to turn.
        return f"turn {format_number(math.pi)} rad", end
    token = tokens[i]
    if (token in _ARTICLES and (i == 0 or tokens[i - 1] not in _TURN_WAYS)
            and (said := _parse_number(tokens, i + 1)) is not None and _unit_at(tokens, said[1]) is None
            and _bare_degrees(tokens, i + 1, *said)):
        # As for a U-turn, the verb stays and the turn is named: "do a 180" asks the robot to turn.
        return f"turn {format_number(math.radians(said[0]))} rad", said[1]
    if (part := _fraction_of(tokens, i)) is not None:
        return part
    parsed = _parse_number(tokens, i)
    if parsed is not None:
        value, j = parsed
        if (unit := _with_unit(tokens, value, j, explicit=True)) is not None:
            return unit
        if _bare_degrees(tokens, i, value, j):
            return f"{format_number(math.radians(value))} rad", j
        return format_number(value), j
    if token in NUMBER_HOMOPHONES:
        nxt = tokens[i + 1] if i + 1 < len(tokens) else ""
        if _in_point(tokens, i):
            return format_number(NUMBER_HOMOPHONES[token]), i + 1
        if nxt == "times" or _unit_at(tokens, i + 1) is not None or _revolutions_at(tokens, i + 1):
            value = float(NUMBER_HOMOPHONES[token])
            unit = _with_unit(tokens, value, i + 1, explicit=True)
            return unit if unit is not None else (format_number(value), i + 1)
        if tokens[i + 1:i + 4] == ["and", "a", "half"] and _unit_at(tokens, i + 4) is not None:
            unit = _with_unit(tokens, NUMBER_HOMOPHONES[token] + 0.5, i + 4, explicit=True)
            if unit is not None:
                return unit
    fraction = _fraction_phrase(tokens, i)
    if fraction is not None:
        value, j = fraction
        unit = _with_unit(tokens, value, j, explicit=False)
        if unit is not None:
            return unit
        # "half a turn", "a quarter turn": fractions of a whole revolution.
        if token in ("half", "quarter", "a") and value < 1 and j < len(tokens) and tokens[j] in _ONE_REVOLUTION:
            return f"{format_number(value * 2 * math.pi)} rad", j + 1
    return None


def _bare_degrees(tokens: Sequence[str], i: int, value: float, end: int) -> bool:
    """Whether the bare number tokens[i:end] follows a turn's way or an article and is too large to be radians."""
    at = i - 2 if tokens[i - 1:i] == ["by"] else i - 1
    before = tokens[at] if at >= 0 else ""
    after = tokens[end:end + 2]
    coordinate = after[:1] == [","] and len(after) == 2 and _is_number_token(after[1])
    return (before in _TURN_WAYS | _ARTICLES and value == int(value) and 2 * math.pi < value <= _LARGEST_BARE_DEGREES
            and after[:1] != ["times"] and not coordinate)


def _fraction_of(tokens: Sequence[str], i: int) -> tuple[str, int] | None:
    """ "a third of a turn", "three quarters of a meter": the fraction of a unit or of a turn, worked out."""
    parsed: tuple[float, int] | None
    if tokens[i:i + 1] in (["a"], ["an"]):
        parsed = 1.0, i + 1
    elif tokens[i:i + 1] and tokens[i].isdigit():
        parsed = float(tokens[i]), i + 1
    else:
        parsed = _parse_integer_words(tokens, i)
    if parsed is None:
        return None
    numerator, j = parsed
    if j >= len(tokens) or tokens[j] not in _DENOMINATORS:
        return None
    value, j = numerator / _DENOMINATORS[tokens[j]], j + 1
    if tokens[j:j + 1] == ["of"] and tokens[j + 1:j + 2] in (["a"], ["an"]):
        j += 2
    if (unit := _with_unit(tokens, value, j, explicit=False)) is not None:
        return unit
    if j < len(tokens) and tokens[j] in _ONE_REVOLUTION:
        return f"{format_number(value * 2 * math.pi)} rad", j + 1
    return None


def _render(tokens: list[str]) -> str:
    words: list[str] = []
    for token in tokens:
        if token == ",":
            if words and words[-1] != ",":
                words.append(",")
            continue
        words.append(token)
    while words and words[0] == ",":
        words.pop(0)
    while words and words[-1] == ",":
        words.pop()
    text = " ".join(words)
    return text.replace(" ,", ",")
