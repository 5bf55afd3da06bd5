"""Speech input: a microphone, Vosk, and a wake word or push-to-talk, giving transcripts."""

from agent.speech.input import SpeechInput, SpeechUnavailable
from agent.speech.records import SpeechConfig, SpeechConfigError, SpeechEvent, Transcript

__all__ = ["SpeechConfig", "SpeechConfigError", "SpeechEvent", "SpeechInput", "SpeechUnavailable", "Transcript"]
