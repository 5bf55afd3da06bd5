"""Text to verified RSL: the on-device LLM, grammar-limited sampling and the compiler repair loop."""

from agent.translate.model_path import ModelNotFoundError
from agent.translate.result import Attempt, TranslationResult
from agent.translate.translator import Options, Translator

__all__ = ["Attempt", "ModelNotFoundError", "Options", "TranslationResult", "Translator"]
