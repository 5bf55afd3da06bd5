"""The phrase list that biases Vosk toward what people say to this robot.

Vosk's runtime grammar is a closed word list: the recogniser then only ever
outputs those words (plus `[unk]` where the model has it). The list is built
from the robot profile (skill keywords and their aliases, or a skill's words
in the language), the objects the robot knows, and the language's number,
unit and joining words, then cut down to the words the model can actually
pronounce.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

from agent.speech.lexicon import Lexicon
from rsl.profile import Profile

UNKNOWN = "[unk]"


@dataclass(frozen=True)
class Vocabulary:
    words: tuple[str, ...]
    # Words that were wanted but are not in the model's lexicon.
    missing: tuple[str, ...]
    has_unknown: bool

    def grammar(self) -> str:
        """The JSON phrase list `KaldiRecognizer` takes."""
        return json.dumps([*self.words, *([UNKNOWN] if self.has_unknown else [])], ensure_ascii=False)

    def __len__(self) -> int:
        return len(self.words)


def supports_runtime_grammar(model_path: str | Path) -> bool:
    """True for lookahead models (HCLr.fst + Gr.fst); a static HCLG graph ignores grammars."""
    graph = Path(model_path) / "graph"
    return (graph / "HCLr.fst").is_file() and (graph / "Gr.fst").is_file()


def wanted_words(profile: Profile, lexicon: Lexicon, objects: Iterable[str] = (),
                 wake_words: Sequence[str] = ()) -> list[str]:
    """Every word worth biasing toward, before checking the model's lexicon."""
    words: list[str] = [*wake_words, *lexicon.stop_words, *lexicon.yes_words, *lexicon.no_words]
    for skill in profile.skills:
        if lexicon.language == "en":
            for name in (skill.keyword, *skill.aliases):
                words.extend(name.split("_"))
        words.extend(skill.words_in(lexicon.language))
    for name in objects:
        spoken = lexicon.object_words.get(name)
        if spoken:
            words.extend(spoken)
        elif lexicon.language == "en":
            words.extend(name.lower().split("_"))
    words.extend(lexicon.numbers)
    words.extend(lexicon.units)
    words.extend(lexicon.connectives)
    return list(dict.fromkeys(w.lower() for w in words if w))


def build_vocabulary(words: Iterable[str], find_word: Callable[[str], int]) -> Vocabulary:
    """Keep the words the model knows (`find_word` is `vosk.Model.vosk_model_find_word`)."""
    known: list[str] = []
    missing: list[str] = []
    for word in dict.fromkeys(words):
        (known if find_word(word) >= 0 else missing).append(word)
    return Vocabulary(words=tuple(known), missing=tuple(missing), has_unknown=find_word(UNKNOWN) >= 0)
