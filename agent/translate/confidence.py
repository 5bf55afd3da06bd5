"""How sure nrtrans is that a verified plan is what the person meant, in [0, 1].

Two signals combine. The model's: the least sure token it chose among the
tokens the grammar allowed (a skill it hesitated over shows here). The
meaning checks' (agent/translate/meaning.py): each disagreement between the
task and the plan cuts the confidence, and its reason is kept so the
question put to the person can say why.
"""

from __future__ import annotations

from collections.abc import Collection, Iterable
from dataclasses import dataclass
from typing import Any

from agent.translate.explain import explain
from agent.translate.meaning import Doubt, check_meaning
from rsl.plan import Plan
from rsl.profile import Profile

# What one disagreement between task and plan leaves of the confidence: any one of them is a likely
# wrong program, so a single doubt puts the plan below UNSURE_BELOW however sure the model was.
DOUBT_FACTOR = 0.3
# The default `confirm = "unsure"` policy asks below this: the lowest threshold at which, over the fourteen
# fresh sets the checks are judged on, at most 2 in 100 items run a wrong program unasked and at most 10 % of
# right programs are questioned (bench/bench_confidence.py's coverage curves; docs/confidence.md).
UNSURE_BELOW = 0.7
POLICIES = ("never", "unsure", "always")


@dataclass(frozen=True)
class Assessment:
    confidence: float
    doubts: tuple[Doubt, ...]
    model: float | None  # the model's own signal, None when the engine gives none

    @property
    def unsure(self) -> bool:
        return self.confidence < UNSURE_BELOW

    @property
    def reasons(self) -> tuple[str, ...]:
        """Why it is unsure, for a person; the model's hesitation when no check failed."""
        if self.doubts:
            return tuple(d.reason for d in self.doubts)
        if self.unsure and self.model is not None:
            return (f"the model was only {self.model:.0%} sure of its choice of words",)
        return ()


def model_signal(probabilities: Iterable[float]) -> float | None:
    """The least sure choice the model made under the grammar; None when it reported none."""
    values = list(probabilities)
    return min(values) if values else None


def assess(task: str, plan: Plan, profile: Profile, *, model: float | None = None,
           known_objects: Collection[str] | None = None) -> Assessment:
    """The confidence of a verified plan for the normalized `task`."""
    doubts = check_meaning(task, plan, profile, known_objects)
    confidence = (1.0 if model is None else model) * DOUBT_FACTOR ** len(doubts)
    return Assessment(confidence=round(min(1.0, max(0.0, confidence)), 4), doubts=doubts, model=model)


def with_doubt(assessment: Assessment, doubt: Doubt) -> Assessment:
    """`assessment` with one more doubt, its confidence cut as `assess` cuts it for each."""
    confidence = round(max(0.0, assessment.confidence * DOUBT_FACTOR), 4)
    return Assessment(confidence=confidence, doubts=(*assessment.doubts, doubt), model=assessment.model)


def asks(policy: str, assessment: Assessment | None) -> bool:
    """Whether `policy` asks the person before the plan runs."""
    if policy == "always":
        return True
    if policy == "never":
        return False
    return assessment is not None and assessment.unsure


def result_fields(plan: Plan, profile: Profile, assessment: Assessment) -> dict[str, Any]:
    """The fields a verified `TranslationResult` carries besides the plan: explanation, confidence, doubts."""
    return {"explanation": explain(plan, profile), "confidence": assessment.confidence,
            "doubts": assessment.reasons, "doubted_by": tuple(d.check for d in assessment.doubts),
            "confirm": asks("unsure", assessment)}
