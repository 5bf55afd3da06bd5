"""The evaluation suite: tasks written for this project, with acceptance checks."""

from agent.evalsuite.suite import GROUPS, EvalTask, accepts, load_suite

__all__ = ["GROUPS", "EvalTask", "accepts", "load_suite"]
