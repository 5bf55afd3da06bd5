"""The one description of RSL's surface syntax that every reader and writer of programs shares."""

from __future__ import annotations

# What a model writes, in place of a program, for words that are not a task for
# this robot. It is a comment, so it also compiles, to an empty plan.
NO_PROGRAM = "// no program"
